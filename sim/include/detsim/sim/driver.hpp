// detsim::FixedStepDriver: runs a World at its fixed dt from a real-time host's variable frames.
//
// The host measures how much real time passed since its last frame and hands it over as integer
// nanoseconds; the driver accumulates it and steps the world once per whole dt in the accumulator
// ("Fix Your Timestep", Glenn Fiedler, 2004). What the world computes depends only on the number of
// steps and the inputs the game applies before each, never on the host's frame times: a 30 Hz, a
// 60 Hz and a 144 Hz host with any jitter produce the same sequence of states. The remainder left
// in the accumulator gives the interpolation factor alpha for rendering between the last two steps.
//
// Time is exact. 1 ns is 2^23 ticks and dt (Q32.32 seconds, raw units of 2^-32 s) is
// dt.raw() * 1953125 ticks, since 10^9 = 2^9 * 1953125: the accumulator holds both exactly, so the
// number of steps after any sequence of frames is floor(total elapsed / dt) exactly, with no
// drift however long the host runs (see docs/SIM.md, "Fixed-timestep driver").
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include <detsim/core/status.hpp>
#include <detsim/fixed/fixed.hpp>
#include <detsim/fixed/quat.hpp>
#include <detsim/fixed/vec3.hpp>
#include <detsim/sim/body.hpp>
#include <detsim/sim/world.hpp>

namespace detsim {

/// How a FixedStepDriver guards the host against long frames. Plain data with defaults.
struct DriverConfig {
  /// The longest frame (ns) accepted at once: 1 .. 10^12 (1000 s). A longer frame (a debugger
  /// break, a hitch, a suspended laptop) counts as this long and the rest is dropped, so one bad
  /// frame cannot demand more steps than the host can run before its next frame (the
  /// "spiral of death"). The default 250 ms is 15 steps at 60 Hz.
  std::int64_t max_frame_ns = 250'000'000;
  /// The most steps one advance() takes: >= 1. A second guard for small dt: whole steps beyond it
  /// are dropped (counted by skipped_steps()); the fraction of a step left is kept. The default
  /// does not bind for dt >= 1/512 s with the default max_frame_ns.
  std::uint32_t max_steps_per_advance = 128;

  friend constexpr bool operator==(const DriverConfig&, const DriverConfig&) noexcept = default;
};

/// A body's pose: where rendering should draw it.
struct Transform {
  Vec3 position{};
  Quat orientation{};

  friend constexpr bool operator==(const Transform&, const Transform&) noexcept = default;
};

/// The fixed-timestep loop of a real-time host. Use one driver per world; call reset() when the
/// world is replaced or restored to a state the driver did not step to (a rollback, a loaded save),
/// otherwise interpolation may blend across the jump for one frame.
///
/// Typical frame:
///
///     driver.advance(world, elapsed_ns, [&](World& w) { game.apply_inputs(w, w.frame()); });
///     for (BodyId id : visible) draw(*driver.interpolated(world, id));
///
/// Rendering is the one place where leaving Fixed is right: convert the interpolated transform's
/// components with Fixed::to_double() for the graphics API; never feed such values back.
class FixedStepDriver {
 public:
  /// The default before_step and after_step: does nothing.
  struct NoInput {
    void operator()(World&) const noexcept {}
  };

  /// A driver, or an error naming the first invalid field of `config`.
  static Expected<FixedStepDriver> create(const DriverConfig& config);

  /// A driver with the default DriverConfig.
  FixedStepDriver() = default;

  [[nodiscard]] const DriverConfig& config() const noexcept { return config_; }

  /// Adds `elapsed_ns` of real time (clamped to config().max_frame_ns; the excess is counted by
  /// dropped_ns()) and steps `world` once per whole world.def().dt in the accumulator, up to
  /// config().max_steps_per_advance times. Before each step it calls `before_step(world)` (a
  /// callable taking World&), where the game applies its inputs for the frame about to be stepped
  /// (world.frame() is that frame), and after it `after_step(world)`, where the game reads what
  /// the step did (events, scores kept beside the world) while world.frame() is the new frame.
  /// Returns the number of steps taken.
  ///
  /// Zero or negative elapsed time (a clock that went backwards) adds no time and is not counted
  /// anywhere; it takes a step only if an interrupted advance left one pending.
  /// An exception from `before_step` propagates; the steps taken until then are accounted for and
  /// the step it interrupted is not taken. One from `after_step` propagates after its step.
  template <class BeforeStep = NoInput, class AfterStep = NoInput>
  std::uint32_t advance(World& world, std::int64_t elapsed_ns, BeforeStep&& before_step = {},
                        AfterStep&& after_step = {}) {
    auto&& before = as_object(before_step);  // a function becomes a pointer kept alive here
    auto&& after = as_object(after_step);
    return advance_erased(world, elapsed_ns, hook(before), hook(after));
  }

  /// advance() with a std::chrono duration (anything implicitly convertible to nanoseconds).
  template <class BeforeStep = NoInput, class AfterStep = NoInput>
  std::uint32_t advance(World& world, std::chrono::nanoseconds elapsed,
                        BeforeStep&& before_step = {}, AfterStep&& after_step = {}) {
    return advance(world, static_cast<std::int64_t>(elapsed.count()),
                   std::forward<BeforeStep>(before_step), std::forward<AfterStep>(after_step));
  }

  /// The clock without the stepping, for a world that something else steps — a net::Session,
  /// which steps it in net::Game::advance and re-simulates on rollback. Adds `elapsed_ns` exactly
  /// as advance() does and returns how many frames are due now (the same number advance() would
  /// step); the host advances its session that many times, calling capture_poses(world) right
  /// before the last, and interpolated() then blends from those poses:
  ///
  ///     const std::uint32_t due = driver.take_due_steps(world, elapsed_ns);
  ///     for (std::uint32_t i = 0; i < due; ++i) {
  ///       if (i + 1 == due) driver.capture_poses(world);
  ///       (void)session.advance_frame(my_input);
  ///     }
  ///     for (BodyId id : visible) draw(*driver.interpolated(world, id));
  ///
  /// A rollback inside that last advance moves bodies from where they were drawn to where they
  /// are: the blend hides the correction. `world` is only read (its dt).
  [[nodiscard]] std::uint32_t take_due_steps(const World& world, std::int64_t elapsed_ns);
  /// The poses to interpolate from: interpolated() blends from them to the current pose while
  /// `world` is one frame past the frame it is at now (else it returns the current pose).
  void capture_poses(const World& world);

  /// How far the accumulated time is into the next step, in [0, 1): the remainder divided by dt,
  /// rounded down (so never 1). 0 before the first advance().
  [[nodiscard]] Fixed alpha() const noexcept;

  /// The pose to render body `id` at: between its pose right before the last step the driver took
  /// (after that step's before_step) and its current pose, by alpha(). Positions are interpolated
  /// linearly (exactly rounded); orientations by normalised linear interpolation along the shorter
  /// arc. At alpha 0 this is the previous pose exactly. The current pose is returned as it is for a
  /// body created since that step, and for every body when `world` has been stepped or restored to
  /// another frame since. Nothing for an ID `world` does not contain.
  [[nodiscard]] std::optional<Transform> interpolated(const World& world, BodyId id) const;

  /// Forgets the accumulated time, the poses before the last step and the counters; keeps the
  /// configuration.
  void reset() noexcept;

  /// The pending time in the accumulator (seconds, rounded down): alpha() times dt.
  [[nodiscard]] Fixed accumulated() const noexcept;
  /// Real time accepted since creation or reset(), after clamping (ns; saturates at the int64 max).
  [[nodiscard]] std::int64_t accepted_ns() const noexcept { return accepted_ns_; }
  /// Real time dropped by the max_frame_ns clamp since creation or reset() (ns; saturates).
  [[nodiscard]] std::int64_t dropped_ns() const noexcept { return dropped_ns_; }
  /// Whole steps of accepted time dropped by max_steps_per_advance since creation or reset().
  [[nodiscard]] std::uint64_t skipped_steps() const noexcept { return skipped_steps_; }
  /// Steps taken since creation or reset().
  [[nodiscard]] std::uint64_t total_steps() const noexcept { return total_steps_; }

 private:
  struct PreviousPose {
    BodyId id{};
    Transform transform{};
  };

  explicit FixedStepDriver(const DriverConfig& config) noexcept : config_(config) {}

  /// A callable by address and how to call it: the callable lives until advance() returns, so a
  /// pointer is enough (no allocation, unlike std::function).
  struct Hook {
    void* callable;
    void (*call)(void*, World&);
  };
  template <class F>
  static decltype(auto) as_object(F& f) noexcept {
    if constexpr (std::is_function_v<F>) {
      return &f;
    } else {
      return (f);
    }
  }
  template <class F>
  static Hook hook(F& f) noexcept {
    static_assert(std::is_invocable_v<F&, World&>,
                  "before_step and after_step must be callable as f(world) with a World&");
    // The const_cast only erases the type: the call restores it.
    return Hook{const_cast<void*>(static_cast<const void*>(std::addressof(f))),
                [](void* callable, World& w) { (*static_cast<F*>(callable))(w); }};
  }
  /// Adds the elapsed time and drops the steps beyond the cap; returns the steps due now.
  std::uint64_t take_time(const World& world, std::int64_t elapsed_ns);
  std::uint32_t advance_erased(World& world, std::int64_t elapsed_ns, Hook before, Hook after);
  void capture_previous_poses(const World& world);

  DriverConfig config_{};
  std::uint64_t accumulator_ticks_ = 0;  ///< < step_ticks_ between calls (2^23 ticks per ns)
  std::uint64_t step_ticks_ = 0;         ///< dt of the world last advanced; 0 before that
  std::int64_t accepted_ns_ = 0;
  std::int64_t dropped_ns_ = 0;
  std::uint64_t skipped_steps_ = 0;
  std::uint64_t total_steps_ = 0;
  std::vector<PreviousPose> previous_;  ///< ascending ID
  /// The world frame that previous_ leads to (the frame after the driver's last step); 0 when
  /// there are no previous poses (a world's frame after a step is never 0).
  std::uint64_t interpolation_frame_ = 0;
};

}  // namespace detsim
