// The Bullet 3 peer of the pile scenes (docs/SCENARIOS.md; docs/BENCHMARKS.md has the figures),
// behind an interface that names no Bullet type: only bullet_peer.cpp includes Bullet's headers,
// so the rest of the benchmark builds without them.
//
// Bullet is single-precision float and a benchmark peer only: it is linked into sim_bench and
// nothing else.
#pragma once

#include <cstdint>
#include <memory>

namespace detsim_bench {

/// N boxes (1 m) or spheres (radius 0.5 m), mass 1, friction 0.5, restitution 0, on a cubic
/// lattice of side ceil(cbrt(N)), spacing 1.1 m, lowest layer at y = 1, centred on x/z, above a
/// static plane at y = 0 (friction 0.5). g = -9.81, 60 Hz, 10 solver iterations: the set-up of the
/// project's Bullet anchor.
///
/// `friction` replaces the 0.5 of every body and of the plane. Bullet combines two frictions by
/// their product and detsim by their geometric mean, so the anchor's 0.5 gives 0.25 at a Bullet
/// contact and 0.5 at a detsim one; kMatchedFriction (sqrt 0.5) gives Bullet's contacts detsim's
/// 0.5, for a cross-check on the same physical scene.
class BulletPile {
 public:
  static constexpr double kAnchorFriction = 0.5;
  static constexpr double kMatchedFriction = 0.70710678118654752;

  BulletPile(std::uint32_t count, bool spheres, double friction = kAnchorFriction);
  ~BulletPile();
  BulletPile(const BulletPile&) = delete;
  BulletPile& operator=(const BulletPile&) = delete;

  /// One fixed step of 1/60 s (no interpolation sub-stepping).
  void step();
  /// The mean height of the bodies' centres (m): a check that the pile fell and settled alike.
  [[nodiscard]] double mean_height() const;
  /// Bodies not deactivated (Bullet's sleeping).
  [[nodiscard]] std::uint32_t awake_count() const;

  /// Bullet's version as an integer (e.g. 324 for 3.24).
  [[nodiscard]] static int version();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The same pile with kMatchedFriction.
class BulletPileMatched : public BulletPile {
 public:
  BulletPileMatched(std::uint32_t count, bool spheres)
      : BulletPile(count, spheres, kMatchedFriction) {}
};

}  // namespace detsim_bench
