// FixedStepDriver: the accumulator, the frame clamp, alpha and the interpolated poses.
#include <detsim/sim/driver.hpp>

#include <algorithm>
#include <limits>
#include <string>

#include <detsim/fixed/math.hpp>
#include <detsim/fixed/wide.hpp>

namespace detsim {

namespace {

// The accumulator's unit, a tick, is 2^-23 ns = 1 / (1953125 * 2^32) s: the largest unit in which
// both a nanosecond (2^23 ticks) and a Q32.32 second's raw unit, 2^-32 s = 10^9 / 2^32 ns
// (1953125 ticks), are whole numbers, because gcd(10^9, 2^32) = 2^9. Counting in ticks, frame times
// and steps add and subtract with no rounding at all, so after any sequence of frames the number of
// steps is exactly floor(total real time / dt).
constexpr std::uint64_t ticks_per_ns = std::uint64_t{1} << 23;
constexpr std::uint64_t ticks_per_raw = 1953125;
static_assert(ticks_per_raw * 512 == 1'000'000'000, "10^9 = 2^9 * 1953125");

// The accumulator never exceeds max_frame_ns plus one step: 10^12 * 2^23 + 2^32 * 1953125
// (dt <= 1 s) < 8.4e18 fits an unsigned 64-bit integer with room to spare.
constexpr std::int64_t max_max_frame_ns = 1'000'000'000'000;
static_assert(static_cast<std::uint64_t>(max_max_frame_ns) * ticks_per_ns +
                      (std::uint64_t{1} << 32) * ticks_per_raw <
                  std::numeric_limits<std::uint64_t>::max() / 2,
              "the accumulator cannot overflow");

constexpr std::int64_t add_saturating(std::int64_t total, std::int64_t more) noexcept {
  // Both are >= 0 here, so only the upper bound can be crossed.
  return more > std::numeric_limits<std::int64_t>::max() - total
             ? std::numeric_limits<std::int64_t>::max()
             : total + more;
}

}  // namespace

Expected<FixedStepDriver> FixedStepDriver::create(const DriverConfig& config) {
  if (config.max_frame_ns < 1 || config.max_frame_ns > max_max_frame_ns) {
    return Status::error("DriverConfig.max_frame_ns must be in 1 .. " +
                         std::to_string(max_max_frame_ns) + " ns (1000 s), got " +
                         std::to_string(config.max_frame_ns));
  }
  if (config.max_steps_per_advance < 1) {
    return Status::error("DriverConfig.max_steps_per_advance must be >= 1, got " +
                         std::to_string(config.max_steps_per_advance));
  }
  return FixedStepDriver(config);
}

std::uint64_t FixedStepDriver::take_time(const World& world, std::int64_t elapsed_ns) {
  const std::int64_t dt_raw = world.def().dt.raw();
  // World validates dt in (0, 1] s; refusing anything else keeps the division below defined even
  // if that ever changed.
  if (dt_raw <= 0 || dt_raw > Fixed::one_raw) return 0;
  step_ticks_ = static_cast<std::uint64_t>(dt_raw) * ticks_per_raw;

  if (elapsed_ns > 0) {
    const std::int64_t accepted = std::min(elapsed_ns, config_.max_frame_ns);
    accepted_ns_ = add_saturating(accepted_ns_, accepted);
    dropped_ns_ = add_saturating(dropped_ns_, elapsed_ns - accepted);
    accumulator_ticks_ += static_cast<std::uint64_t>(accepted) * ticks_per_ns;
  }

  // Steps beyond the cap are dropped before stepping (keeping the fraction of a step), so the
  // accumulator stays below one step plus one frame and never grows from advance to advance.
  const std::uint64_t due = accumulator_ticks_ / step_ticks_;
  const std::uint64_t steps = std::min<std::uint64_t>(due, config_.max_steps_per_advance);
  if (due > steps) {
    skipped_steps_ += due - steps;
    accumulator_ticks_ -= (due - steps) * step_ticks_;
  }
  return steps;
}

std::uint32_t FixedStepDriver::advance_erased(World& world, std::int64_t elapsed_ns, Hook before,
                                              Hook after) {
  const std::uint64_t steps = take_time(world, elapsed_ns);
  for (std::uint64_t i = 0; i < steps; ++i) {
    before.call(before.callable, world);
    if (i + 1 == steps) {
      // The poses the last step starts from, after the game's inputs (a teleport in before_step
      // is then not drawn as a sweep across the world).
      interpolation_frame_ = 0;
      capture_previous_poses(world);
    }
    world.step();
    accumulator_ticks_ -= step_ticks_;
    ++total_steps_;
    if (i + 1 == steps) interpolation_frame_ = world.frame();
    after.call(after.callable, world);
  }
  return static_cast<std::uint32_t>(steps);
}

std::uint32_t FixedStepDriver::take_due_steps(const World& world, std::int64_t elapsed_ns) {
  const std::uint64_t steps = take_time(world, elapsed_ns);
  accumulator_ticks_ -= steps * step_ticks_;
  total_steps_ += steps;
  if (steps > 0) interpolation_frame_ = 0;  // until capture_poses() names the new start
  return static_cast<std::uint32_t>(steps);
}

void FixedStepDriver::capture_poses(const World& world) {
  capture_previous_poses(world);
  interpolation_frame_ = world.frame() + 1;
}

void FixedStepDriver::capture_previous_poses(const World& world) {
  previous_.clear();  // keeps the capacity: no allocation per frame once the body count settles
  for (const BodyId id : world.body_ids()) {
    const auto body = world.body(id);
    if (body.ok()) previous_.push_back({id, Transform{body->position, body->orientation}});
  }
}

Fixed FixedStepDriver::alpha() const noexcept {
  if (step_ticks_ == 0) return Fixed::zero();
  // Only an exception from before_step can leave a whole step in the accumulator.
  if (accumulator_ticks_ >= step_ticks_) return Fixed::from_raw(Fixed::one_raw - 1);
  // floor(acc * 2^32 / step): the quotient is below 2^32 because acc < step, so it is < 1.
  const wide::U128 scaled = wide::shl(wide::U128{0, accumulator_ticks_}, Fixed::fraction_bits);
  return Fixed::from_raw(
      static_cast<std::int64_t>(wide::Default::div(scaled, step_ticks_).quotient));
}

Fixed FixedStepDriver::accumulated() const noexcept {
  return Fixed::from_raw(static_cast<std::int64_t>(accumulator_ticks_ / ticks_per_raw));
}

std::optional<Transform> FixedStepDriver::interpolated(const World& world, BodyId id) const {
  const auto body = world.body(id);
  if (!body.ok()) return std::nullopt;
  const Transform current{body->position, body->orientation};
  if (interpolation_frame_ == 0 || world.frame() != interpolation_frame_) return current;
  const auto it =
      std::lower_bound(previous_.begin(), previous_.end(), id,
                       [](const PreviousPose& pose, BodyId key) { return pose.id < key; });
  if (it == previous_.end() || it->id != id) return current;
  const Transform& previous = it->transform;

  const Fixed t = alpha();
  if (t == Fixed::zero()) return previous;
  Transform result;
  result.position = {lerp(previous.position.x, current.position.x, t),
                     lerp(previous.position.y, current.position.y, t),
                     lerp(previous.position.z, current.position.z, t)};
  if (previous.orientation == current.orientation) {
    result.orientation = current.orientation;
    return result;
  }
  // Normalised lerp: q and -q are the same rotation, so flip the start onto the end's hemisphere
  // to take the shorter arc (and never pass through the zero quaternion). Between two steps the
  // rotation is small, where nlerp's uneven angular speed is far below what a frame can show.
  Quat from = previous.orientation;
  if (dot(from, current.orientation) < Fixed::zero()) from = {-from.w, -from.x, -from.y, -from.z};
  const Quat& to = current.orientation;
  result.orientation = normalize(Quat{lerp(from.w, to.w, t), lerp(from.x, to.x, t),
                                      lerp(from.y, to.y, t), lerp(from.z, to.z, t)});
  return result;
}

void FixedStepDriver::reset() noexcept {
  accumulator_ticks_ = 0;
  step_ticks_ = 0;
  accepted_ns_ = 0;
  dropped_ns_ = 0;
  skipped_steps_ = 0;
  total_steps_ = 0;
  previous_.clear();
  interpolation_frame_ = 0;
}

}  // namespace detsim
