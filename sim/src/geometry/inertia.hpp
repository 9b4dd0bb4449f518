// Inertia tensors: the principal frame of a symmetric 3x3 tensor and the parallel-axis shift.
// Shared by the hull's mass properties (hull_mass.cpp) and compounds. Internal to detsim::sim.
#pragma once

#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/mat3.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>

namespace detsim::sim_detail {

/// The eigenvalues and eigenvectors of a symmetric tensor: tensor = R diag(moments) R^T with
/// R = to_mat3(axes) (columns are the principal axes, in the tensor's frame).
struct PrincipalFrame {
  Vec3 moments;
  Quat axes = Quat::identity();
};

/// The most Jacobi sweeps principal_frame runs. A 3x3 tensor converges quadratically and in
/// Fixed reaches exact zeros off the diagonal in 4 to 6 sweeps; the cap bounds the work for any
/// input.
inline constexpr int max_jacobi_sweeps = 12;

/// The principal moments and axes of the symmetric tensor `tensor` (its upper triangle is read;
/// the lower is taken to mirror it), by cyclic Jacobi rotations in Fixed arithmetic: the same bits
/// on every platform. A tensor that is already diagonal (every off-diagonal entry exactly zero)
/// gives its diagonal and exactly the identity quaternion. The moments are not sorted: moment i
/// belongs to column i of to_mat3(axes). Accuracy: the tensor is scaled by a power of two so that
/// its largest entry lies in [1, 2) before rotating, so the moments are within a few 2^-32 of the
/// largest entry (relative) and R diag(moments) R^T reproduces the tensor to about 2^-28 of it.
[[nodiscard]] PrincipalFrame principal_frame(const Mat3& tensor) noexcept;

/// The inertia tensor per unit mass about a point at `offset` from the centroid, given the tensor
/// per unit mass about the centroid (the parallel-axis theorem): I + |d|^2 E - d d^T. Multiply by
/// the mass for the tensor of a part of a compound about the compound's reference point.
[[nodiscard]] Mat3 shift_inertia(const Mat3& about_centroid_per_mass, Vec3 offset) noexcept;

/// The unit quaternion of a rotation matrix (Shepperd's method: the largest of w, x, y, z is taken
/// from the diagonal, the others from the off-diagonal sums, so that no division is by a small
/// number); w >= 0. The identity matrix gives exactly Quat::identity().
[[nodiscard]] Quat quat_from_rotation(const Mat3& rotation) noexcept;

}  // namespace detsim::sim_detail
