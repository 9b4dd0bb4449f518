#!/usr/bin/env python3
"""Writes docs/BENCHMARKS.md from the JSON output of bench/sim_bench and bench/fixed_bench.

Called by scripts/bench.sh; standard library only. Figures are reported, never asserted: this
script never fails because a number is bad, only because its input is unreadable.

Per benchmark it takes the repetitions (run_type "iteration") and reports the minimum over them as
the headline figure, with the median beside it: for fixed_bench ns per call from items_per_second,
for sim_bench CPU time per call or per step. Both come from CPU time. The minimum is used because
noise on a shared machine (other processes, cache and frequency interference) only ever adds time.
Ratios between two figures are ratios of their minima, measured in the same run of one program.
"""

import argparse
import datetime
import json
import math
import platform
import shutil
import statistics
import subprocess
import sys

# (function, detsim goal as a throughput ratio to double, from the performance issue)
FUNCTIONS = [
    ("mul", 0.8),
    ("div", 0.3),
    ("sqrt", 0.5),
    ("sin", 1.0),
    ("cos", 1.0),
    ("atan2", 1.0),
    ("exp", 1.0),
    ("log", 1.0),
]
EXTRA = ["sin_wide"]

IMPLEMENTATIONS = [
    ("double", "double (glibc)"),
    ("detsim", "detsim Fixed (Q32.32)"),
    ("libfixmath", "libfixmath (Q16.16)"),
    ("libfixmath_repeat", "libfixmath, one block repeated (its memo caches hit)"),
]

# detsim promises <= 1 ulp (2^-32) where |result| < 2^16 and relative 2^-46 above; the largest
# result in these domains is e^10 ~ 22026. Anything beyond this bound is a wrong result (a
# placeholder or a bug), and the timing of a wrong result says nothing.
DETSIM_SANITY_BOUND = 1e-6


def lscpu():
    """lscpu's fields as a dict (empty where lscpu is missing)."""
    if not shutil.which("lscpu"):
        return {}
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True,
                             env={"LC_ALL": "C", "PATH": "/usr/bin:/bin"}).stdout
    except (OSError, subprocess.CalledProcessError):
        return {}
    fields = {}
    for line in out.splitlines():
        key, sep, value = line.partition(":")
        if sep:
            fields[key.strip()] = value.strip()
    return fields


def compiler_banner(compiler_path):
    if not compiler_path:
        return None
    try:
        out = subprocess.run([compiler_path, "--version"], capture_output=True, text=True,
                             check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    return out.splitlines()[0] if out else None


def collect(benchmarks):
    """{name: {"ns": [ns per call per repetition], "err": max_abs_err, "label": domain}}"""
    runs = {}
    for b in benchmarks:
        if b.get("run_type", "iteration") != "iteration" or "error_occurred" in b:
            continue
        rate = b.get("items_per_second")
        if not rate:
            continue
        entry = runs.setdefault(b["run_name"], {"ns": [], "err": 0.0, "label": b.get("label", "")})
        entry["ns"].append(1e9 / rate)
        err = b.get("max_abs_err", 0.0)
        if math.isnan(err) or err > entry["err"]:  # a NaN sticks: it marks wrong results
            entry["err"] = err
    return runs


def fmt_ns(ns):
    if ns is None:
        return "—"
    if ns >= 100:
        return f"{ns:.0f}"
    if ns >= 10:
        return f"{ns:.1f}"
    return f"{ns:.2f}"


def fmt_ratio(r):
    if r is None:
        return "—"
    return f"{r:.2f}" if r >= 0.1 else f"{r:.2g}"


def fmt_err(e):
    return "0" if e == 0 else f"{e:.2g}"


def fmt_rate(ns):
    if ns is None:
        return "—"
    per_second = 1e9 / ns
    if per_second >= 1e9:
        return f"{per_second / 1e9:.2f} G"
    return f"{per_second / 1e6:.1f} M"


def best(run):
    return min(run["ns"]) if run else None


def median(run):
    return statistics.median(run["ns"]) if run else None


def ratio(reference, other):
    """Throughput of `other` relative to `reference` (> 1: other is faster)."""
    if reference is None or other is None:
        return None
    return reference / other


def goal_status(run, ratio_value, goal):
    if run is None or ratio_value is None:
        return "not measured"
    if not run["err"] <= DETSIM_SANITY_BOUND:
        return f"invalid: results wrong (max error {fmt_err(run['err'])}), timing meaningless"
    return "met" if ratio_value >= goal else "not met"


# ---- Simulation (bench/sim_bench) --------------------------------------------------------------

# Goals from the simulation benchmark issue.
SIM_SPEED_GOAL = 1.0      # detsim ms/step <= this times Bullet's, per pile scene
STATE_OP_GOAL = 5.0       # save, restore, hash: <= this % of one step
BYTES_PER_BODY_GOAL = 150.0
ROLLBACK_GOAL = 8.5       # restore + 8 steps <= this times one step
SLEEP_GOAL = 10.0         # a step of a sleeping pile <= this % of an awake step

TIME_UNIT_MS = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}


def sim_key(run_name):
    """'pile_boxes/detsim/iterations:1' -> 'pile_boxes/detsim'."""
    return "/".join(part for part in run_name.split("/")
                    if not part.startswith(("iterations:", "repeats:", "min_time:")))


def collect_sim(benchmarks):
    """{key: [repetition, ...]}; a repetition is {"cpu_ms", "real_ms", counters...} per iteration."""
    runs = {}
    for b in benchmarks:
        if b.get("run_type", "iteration") != "iteration" or "error_occurred" in b:
            continue
        scale = TIME_UNIT_MS.get(b.get("time_unit", "ns"), 1e-6)
        rep = {k: v for k, v in b.items() if isinstance(v, (int, float))}
        rep["cpu_ms"] = b["cpu_time"] * scale
        rep["real_ms"] = b["real_time"] * scale
        runs.setdefault(sim_key(b.get("run_name", b["name"])), []).append(rep)
    return runs


def per_step(rep):
    return rep["cpu_ms"] / rep.get("steps_per_iteration", 1)


def stat(reps, field, fn=min):
    """fn over the repetitions of a field (a callable field is applied to each repetition)."""
    if not reps:
        return None
    values = [field(r) if callable(field) else r.get(field) for r in reps]
    values = [v for v in values if v is not None]
    return fn(values) if values else None


def fmt_ms(ms):
    if ms is None:
        return "—"
    if ms >= 100:
        return f"{ms:.0f} ms"
    if ms >= 1:
        return f"{ms:.2f} ms"
    if ms >= 0.01:
        return f"{ms * 1e3:.0f} µs"
    return f"{ms * 1e3:.2f} µs"


def fmt_num(x, digits=2):
    return "—" if x is None else f"{x:.{digits}f}"


def status_le(value, goal):
    if value is None:
        return "not measured"
    return "met" if value <= goal else "not met"


def render_sim(data, args, add):
    context = data.get("context", {})
    runs = collect_sim(data.get("benchmarks", []))
    count = context.get("pile_count", "?")
    steps = context.get("pile_steps", "?")
    window = context.get("pile_window", "?")
    frame = context.get("pile_state_frame", "?")
    rollback_frames = int(context.get("rollback_frames", "8"))
    sleep_max = context.get("pile_sleep_max_frames", "?")
    bullet = context.get("bullet_version", "")
    have_bullet = bullet.isdigit()
    bullet_name = f"Bullet {int(bullet) // 100}.{int(bullet) % 100:02d}" if have_bullet else "Bullet"
    reps = max((len(r) for k, r in runs.items() if k.startswith("pile_")), default=0)

    add("## Simulation: detsim beside Bullet, state and rollback costs")
    add("")
    add(f"`bench/sim_bench`; {reps} repetitions of each whole run (the state benchmarks' counts are "
        "in their table), all randomly interleaved, so detsim and "
        f"{bullet_name if have_bullet else 'the peer'} shared the same moments of the machine. Every "
        "figure is CPU time of the benchmark thread, the minimum over the repetitions.")
    if not have_bullet:
        add("")
        add("> **Bullet was not found when this was built**, so no ratio to it was measured "
            "(install `libbullet-dev`, or run `scripts/install-deps.sh`, and re-run).")
    add("")

    # ---- the figures the goals are about ----
    rollback_runs = runs.get("state/rollback8", [])
    one_step = stat(rollback_runs, "step_ms")
    whole = {}
    filtered = {}
    for scene in ("pile_boxes", "pile_spheres"):
        d = stat(runs.get(f"{scene}/detsim"), per_step)
        b = stat(runs.get(f"{scene}/bullet"), per_step)
        whole[scene] = (d, b)
        # The counter only falls as repetitions accumulate: its minimum covers them all.
        fd = stat(runs.get(f"{scene}/detsim"), "ms_per_step_best_steps")
        fb = stat(runs.get(f"{scene}/bullet"), "ms_per_step_best_steps")
        filtered[scene] = (fd, fb)

    def pct(ms):
        return None if ms is None or not one_step else 100.0 * ms / one_step

    save = stat(runs.get("state/save"), "cpu_ms")
    restore = stat(runs.get("state/restore"), "cpu_ms")
    hashing = stat(runs.get("state/hash"), "cpu_ms")
    rollback = stat(rollback_runs, "rollback_ms")
    sleeping = stat(runs.get("sleep/step_sleeping"), "cpu_ms")
    bytes_frame = stat(runs.get("state/save"), "bytes_per_body")
    bytes_settled = stat(runs.get("sleep/step_sleeping"), "bytes_per_body")
    bytes_worst = max((x for x in (bytes_frame, bytes_settled) if x is not None), default=None)
    sleep_runs = runs.get("sleep/step_sleeping", [])
    all_asleep = stat(sleep_runs, "all_asleep")
    awake_left = stat(sleep_runs, "awake")
    settled_frame = stat(sleep_runs, "frame")
    awake_at_frame = stat(rollback_runs, "awake")

    add("### Summary")
    add("")
    awake_text = ("" if awake_at_frame is None else
                  f" ({awake_at_frame:.0f} of {count} bodies awake at frame {frame})")
    add(f"Scene size: {count} bodies. \"One step\" below is one step of the box pile after frame "
        f"{frame}: the mean of the {rollback_frames} steps after it, timed inside the rollback "
        f"benchmark{awake_text}. Ratios are of figures measured in the same run.")
    add("")
    add("| figure | detsim | reference | ratio | goal | status |")
    add("|---|--:|--:|--:|--:|---|")
    for scene, title in (("pile_boxes", "boxes"), ("pile_spheres", "spheres")):
        d, b = whole[scene]
        r = d / b if d is not None and b is not None else None
        # The speed goal counts as met only when the whole-run ratio and the load-filtered one
        # agree: on a shared machine one of them alone can flatter either engine.
        fd, fb = filtered[scene]
        rf = fd / fb if fd is not None and fb is not None else None
        status = status_le(r, SIM_SPEED_GOAL)
        if rf is not None and r is not None and (r <= SIM_SPEED_GOAL) != (rf <= SIM_SPEED_GOAL):
            status = (f"unsettled: the load-filtered ratio is {rf:.2f}× (below); "
                      "needs a quieter machine")
        d_h = stat(runs.get(f"{scene}/detsim"), "mean_height")
        b_h = stat(runs.get(f"{scene}/bullet"), "mean_height")
        if d_h is not None and b_h is not None and abs(d_h - b_h) > 0.2 * max(d_h, b_h):
            status += "; the two scenes ended differently (see the pile table)"
        add(f"| `{scene}`, {title}: ms/step over the {steps}-step run | {fmt_ms(d)} | "
            f"{bullet_name}: {fmt_ms(b)} | {fmt_num(r)}× | ≤ {SIM_SPEED_GOAL:g}× | "
            f"{status} |")
    # The same physical scene (Bullet's contacts given detsim's friction; the pile table says
    # why): the anchor's set-up alone can flatter detsim when Bullet's pile collapses.
    for scene, title in (("pile_boxes", "boxes"), ("pile_spheres", "spheres")):
        d = whole[scene][0]
        m = stat(runs.get(f"{scene}/bullet_matched"), per_step)
        if d is None or m is None:
            continue
        r = d / m
        fd = filtered[scene][0]
        fm = stat(runs.get(f"{scene}/bullet_matched"), "ms_per_step_best_steps")
        rf = fd / fm if fd is not None and fm else None
        status = status_le(r, SIM_SPEED_GOAL)
        if rf is not None and (r <= SIM_SPEED_GOAL) != (rf <= SIM_SPEED_GOAL):
            status = f"unsettled: the load-filtered ratio is {rf:.2f}×"
        add(f"| `{scene}`, {title}, friction matched (the same physical scene; a cross-check "
            f"beside the anchor's set-up) | {fmt_ms(d)} | {bullet_name}, friction matched: "
            f"{fmt_ms(m)} | {fmt_num(r)}× | ≤ {SIM_SPEED_GOAL:g}× | {status} |")
    for name, ms in (("save", save), ("restore", restore), ("hash (all parts)", hashing)):
        p = pct(ms)
        add(f"| {name} of the {count}-box world at frame {frame} | {fmt_ms(ms)} | one step: "
            f"{fmt_ms(one_step)} | {fmt_num(p, 1)} % | ≤ {STATE_OP_GOAL:g} % | "
            f"{status_le(p, STATE_OP_GOAL)} |")
    add(f"| snapshot bytes per dynamic body (with its share of the contact cache; the larger of "
        f"frame {frame} and the settled pile) | {fmt_num(bytes_worst, 0)} B | "
        f"frame {frame}: {fmt_num(bytes_frame, 0)} B, settled: {fmt_num(bytes_settled, 0)} B | | "
        f"≤ {BYTES_PER_BODY_GOAL:g} B | {status_le(bytes_worst, BYTES_PER_BODY_GOAL)} |")
    rb = stat(rollback_runs, "rollback_ratio")
    add(f"| {rollback_frames}-frame rollback: restore + {rollback_frames} steps from frame {frame} | "
        f"{fmt_ms(rollback)} | one step: {fmt_ms(one_step)} | {fmt_num(rb)}× | ≤ {ROLLBACK_GOAL:g}× | "
        f"{status_le(rb, ROLLBACK_GOAL)} |")
    sp = pct(sleeping)
    if all_asleep is None:
        sleep_status = "not measured"
        sleep_where = ""
    elif all_asleep >= 1:
        sleep_status = status_le(sp, SLEEP_GOAL)
        sleep_where = f" (every body asleep from frame {settled_frame:.0f})"
    else:
        sleep_status = (f"not measured as asked: {awake_left:.0f} bodies still awake at frame "
                        f"{settled_frame:.0f}")
        sleep_where = f" (NOT fully asleep: the pile at frame {settled_frame:.0f})"
    add(f"| a step of the settled, sleeping box pile{sleep_where} | {fmt_ms(sleeping)} | "
        f"awake step: {fmt_ms(one_step)} | {fmt_num(sp, 1)} % | ≤ {SLEEP_GOAL:g} % | {sleep_status} |")
    add("")
    parts = []
    for scene in ("pile_boxes", "pile_spheres"):
        fd, fb = filtered[scene]
        if fd is not None and fb is not None:
            parts.append(f"`{scene}` {fmt_ms(fd)} vs {fmt_ms(fb)}, {fd / fb:.2f}×")
    if parts:
        add("Load-filtered cross-check of the two speed ratios (each step's best time over the "
            "repetitions, averaged over the run; both engines are deterministic, so a step does "
            "the same work in every repetition): " + "; ".join(parts) + ".")
        add("")
    if rb is not None:
        add(f"The rollback ratio is (restore + {rollback_frames} steps) / (one of those steps), "
            "both parts read with the thread's CPU clock in the same iteration and the best "
            "iteration kept, so that it is not skewed by load that changes between two "
            "benchmarks; it can only exceed "
            f"{rollback_frames} by the restore's share of a step.")
        add("")
    # ---- the pile runs in detail ----
    add("### The pile scenes")
    add("")
    add(f"One run = the scene built (untimed), then {steps} steps from the drop, each timed. "
        f"\"first {window}\" and \"last {window}\" are the mean ms/step over those steps of the same "
        "run (the drop and impacts, then the settled phase). Mean height and awake bodies are read "
        "after the last step: they show whether the two engines ended in comparable states.")
    add("")
    add(f"| scene | engine | ms/step, whole run (min) | (median) | per-step best | first {window} "
        f"| last {window} | wall ms/step (min) | mean height at end | awake at end |")
    add("|---|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    for scene in ("pile_boxes", "pile_spheres"):
        for engine, title in (("detsim", "detsim"), ("bullet", bullet_name),
                              ("bullet_matched", f"{bullet_name}, friction matched")):
            r = runs.get(f"{scene}/{engine}")
            if not r:
                continue
            add(f"| `{scene}` | {title} | {fmt_ms(stat(r, per_step))} | "
                f"{fmt_ms(stat(r, per_step, statistics.median))} | "
                f"{fmt_ms(stat(r, 'ms_per_step_best_steps'))} | "
                f"{fmt_ms(stat(r, 'ms_per_step_first'))} | {fmt_ms(stat(r, 'ms_per_step_last'))} | "
                f"{fmt_ms(stat(r, lambda x: x['real_ms'] / x.get('steps_per_iteration', 1)))} | "
                f"{fmt_num(stat(r, 'mean_height'))} m | {fmt_num(stat(r, 'awake_at_end'), 0)} |")
    add("")
    for scene in ("pile_boxes", "pile_spheres"):
        d_h = stat(runs.get(f"{scene}/detsim"), "mean_height")
        b_h = stat(runs.get(f"{scene}/bullet"), "mean_height")
        if d_h is not None and b_h is not None and abs(d_h - b_h) > 0.25:
            add(f"- `{scene}`: the engines did not end alike (mean height {d_h:.2f} m in detsim, "
                f"{b_h:.2f} m in {bullet_name}): the columns of the lattice stand in one and "
                "collapse in the other, so the two runs do not do the same work after the drop: "
                f"neither the whole runs nor the last {window} steps compare like with like, and "
                f"the first {window} steps (the drop, before the columns part ways) come "
                "closest.")
    matched = [(scene, runs.get(f"{scene}/detsim"), runs.get(f"{scene}/bullet_matched"))
               for scene in ("pile_boxes", "pile_spheres")]
    matched = [(scene, d, m) for scene, d, m in matched if d and m]
    if matched:
        add(f"- Friction matched: the anchor gives every Bullet body friction 0.5, which Bullet "
            "combines by product (0.25 at a contact) and detsim by geometric mean (0.5). The "
            f"\"friction matched\" rows give Bullet's bodies √0.5, so its contacts have detsim's "
            "0.5: the same physical scene. Ratios of detsim to it in the same run:")
        for scene, d, m in matched:
            parts = []
            for label, key in (("whole run", per_step), ("per-step best", "ms_per_step_best_steps"),
                               (f"first {window}", "ms_per_step_first"),
                               (f"last {window}", "ms_per_step_last")):
                a, b = stat(d, key), stat(m, key)
                if a is not None and b:
                    parts.append(f"{label} {fmt_num(a / b)}×")
            add(f"  - `{scene}`: {', '.join(parts)}; mean height at end "
                f"{fmt_num(stat(d, 'mean_height'))} m vs {fmt_num(stat(m, 'mean_height'))} m.")
    add("")

    # ---- state and sleep in detail ----
    add("### State, rollback and sleep")
    add("")
    add("| benchmark | what one call does | repetitions | CPU per call (min) | (median) | "
        "wall (min) | frame | awake | snapshot bytes | bytes/body |")
    add("|---|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    what = {
        "state/save": "`World::save()` into a new byte vector",
        "state/restore": "`World::restore()`, full validation included",
        "state/hash": "`World::hashes()`: the total and the four part hashes",
        "state/rollback8": f"restore + {rollback_frames} steps",
        "sleep/step_sleeping": "one step of the settled pile",
    }
    for key, text in what.items():
        r = runs.get(key)
        if not r:
            continue
        add(f"| `{key}` | {text} | {len(r)} | {fmt_ms(stat(r, 'cpu_ms'))} | "
            f"{fmt_ms(stat(r, 'cpu_ms', statistics.median))} | {fmt_ms(stat(r, 'real_ms'))} | "
            f"{fmt_num(stat(r, 'frame'), 0)} | {fmt_num(stat(r, 'awake'), 0)} | "
            f"{fmt_num(stat(r, 'snapshot_bytes'), 0)} | {fmt_num(stat(r, 'bytes_per_body'), 1)} |")
    add("")
    if rollback_runs:
        add("CPU per call is Google Benchmark's mean over the iterations of a repetition, so a "
            "moment of heavy load inside a repetition raises it. "
            f"Inside `state/rollback8` (best iteration of each kind): restore + {rollback_frames} "
            f"steps {fmt_ms(rollback)}, the restore {fmt_ms(stat(rollback_runs, 'restore_ms'))}, "
            f"one step {fmt_ms(one_step)} "
            f"(median over repetitions {fmt_ms(stat(rollback_runs, 'step_ms', statistics.median))}), "
            f"rollback ratio {fmt_num(rb)}× (median "
            f"{fmt_num(stat(rollback_runs, 'rollback_ratio', statistics.median))}×).")
        add("")
    if whole["pile_boxes"][0] is not None and one_step:
        add(f"For scale: the mean step of the whole {steps}-step box run is "
            f"{fmt_ms(whole['pile_boxes'][0])}; against it save, restore and hash are "
            f"{fmt_num(100 * save / whole['pile_boxes'][0] if save else None, 1)} %, "
            f"{fmt_num(100 * restore / whole['pile_boxes'][0] if restore else None, 1)} % and "
            f"{fmt_num(100 * hashing / whole['pile_boxes'][0] if hashing else None, 1)} %, and the "
            f"sleeping step {fmt_num(100 * sleeping / whole['pile_boxes'][0] if sleeping else None, 1)} %.")
        add("")

    add("### Method")
    add("")
    add(f"- Scenes: `pile_boxes` and `pile_spheres` (docs/SCENARIOS.md): {count} boxes of 1 m or "
        "spheres of radius 0.5 m, mass 1, friction 0.5, restitution 0, on a cubic lattice (spacing "
        "1.1 m, lowest layer at y = 1) dropped onto a static plane; g = −9.81, 60 Hz. detsim builds "
        "them with `Scenario::create`; `bench/bullet_peer.cpp` builds the same lattice in "
        f"{bullet_name} (`btDiscreteDynamicsWorld`, dynamic AABB tree broadphase, sequential impulse "
        "solver, 10 iterations, one fixed step of 1/60 s per call, default sleeping).")
    add(f"- The solvers differ by design: detsim runs its default `WorldDef` "
        f"({context.get('detsim_substeps', '?')} sub-steps × {context.get('detsim_iterations', '?')} "
        "iteration with relaxation, soft contacts, Q32.32 fixed point); Bullet runs 10 iterations "
        "in float. Bullet combines two frictions by their product (0.5 × 0.5 = 0.25 at a contact), "
        "detsim by their geometric mean (0.5); the peer keeps the anchor's per-body 0.5, and "
        "the friction-matched rows (`<scene>/bullet_matched`) give it √0.5.")
    add(f"- Whole run: the {steps} steps from the drop, the window the project's anchor times. One "
        f"iteration per repetition; the scene is rebuilt (untimed) for each. The first and last "
        f"{window} steps are read from the same run with the thread's CPU clock around each step. "
        "\"Per-step best\" is the mean over the run of each step's best time over the "
        "repetitions: on this virtual machine a single step sometimes takes tens of times its "
        "usual CPU time (the virtual CPU is descheduled while the thread runs), and this filters "
        "those moments out.")
    add("- Headline ms/step: Google Benchmark's CPU time of the run divided by its steps, the "
        "minimum over the repetitions (wall time beside it shows how much the machine's load "
        "delayed the run).")
    add(f"- State figures: the box pile is run to frame {frame} once (untimed) and saved; each "
        "benchmark restores that snapshot into its own world. The rollback benchmark restores it "
        f"and steps {rollback_frames} frames per iteration; \"one step\" is the mean of those "
        "steps. Save, restore, hash and the sleeping step are short, so they get more, shorter "
        "repetitions (the table gives the count) for their minimum to come from a quiet moment.")
    add(f"- Bytes per body: the whole snapshot (header, world definition, RNG, the static ground, "
        "every contact with its warm-start impulses) divided by the number of dynamic bodies.")
    add(f"- Sleeping: the pile is run on from frame {frame} until every dynamic body sleeps (at most "
        f"to frame {sleep_max}), saved, restored, then stepped; the awake step is \"one step\" above.")
    add("- Running by hand: `build-bench/bench/sim_bench --benchmark_filter='^state/'`; "
        "`--pile_count=N`, `--pile_steps=N`, `--pile_window=N`, `--pile_state_frame=N` and "
        "`--pile_sleep_max_frames=N` change the scene and the windows.")
    add("")


# ---- Fixed-point layer (bench/fixed_bench) -------------------------------------------------------


def render_fixed(data, args, add):
    context = data.get("context", {})
    runs = collect(data.get("benchmarks", []))
    reps = max((len(r["ns"]) for r in runs.values()), default=0)

    add("## Fixed-point layer: detsim Fixed vs glibc double vs libfixmath")
    add("")
    add(f"`bench/fixed_bench`; {reps} repetitions per benchmark, randomly interleaved.")
    add("")
    add("### Method")
    add("")
    add("- One seeded pool of inputs per function, inside a domain all three types represent; every "
        "input is rounded to a multiple of 2^-16 first, so the three implementations see exactly "
        "the same real numbers.")
    add(f"- One iteration computes `out[i] = f(in[i])` over a block of {context.get('detsim_block_size', '4096')} "
        "inputs; the output escapes through `benchmark::DoNotOptimize` and `ClobberMemory`.")
    add("- libfixmath memoises sin (so cos), atan2 and exp (which its log calls) in 4096-entry "
        "caches. Those functions cycle through 16 blocks (65536 distinct inputs), for all three "
        "types, so the caches rarely hit; the `libfixmath, one block repeated` row shows what the "
        "caches are worth when inputs repeat. mul, div and sqrt use one block.")
    add("- The compiler decides whether a loop is vectorised: GCC 12 at -O2 keeps the double mul "
        "and div loops scalar, clang at -O2 vectorises them, which makes those two baselines "
        "several times faster. The figures hold for the compiler named above.")
    align = context.get("detsim_fixed_bench_flags", "")
    if align:
        add(f"- The benchmark program alone is compiled with `{align}`: every timed loop (double, "
            "detsim and libfixmath alike) starts on a 64-byte boundary. Where the linker happens to "
            "place a short loop changes its speed: the double mul loop ran at 0.31 or 0.55 ns per "
            "call in two builds that differed only in unrelated code. The detsim library is built "
            "without it, as a user builds it.")
    else:
        add("- The timed loops are not aligned (the compiler lacks `-falign-loops`): a short loop's "
            "speed can depend on where the linker places it.")
    add(f"- **ns/op** is CPU time per call. The headline is the **minimum over the {reps} "
        "repetitions** (noise on a shared machine only adds time); the median is beside it.")
    add("- **vs double** is the throughput ratio double ns / other ns: above 1 means faster than "
        "glibc double. The goal is the issue's target for detsim relative to double.")
    add("- **max abs err** is the largest |result − glibc double| over the inputs: a sanity check "
        "that the benchmark computes the function, not an accuracy measurement (docs/ACCURACY.md "
        "has those). A detsim figure whose results are wrong is marked invalid.")
    add("")

    add("Running by hand: `build-bench/bench/fixed_bench --benchmark_filter='^sin/'` (names are "
        "`<function>/<implementation>`; `--benchmark_list_tests` lists them).")
    add("")
    add("### Summary")
    add("")
    add("| function | double ns/op | detsim ns/op | libfixmath ns/op | detsim vs double | "
        "libfixmath vs double | detsim goal | status |")
    add("|---|--:|--:|--:|--:|--:|--:|---|")
    for name, goal in FUNCTIONS:
        d = runs.get(f"{name}/double")
        f = runs.get(f"{name}/detsim")
        q = runs.get(f"{name}/libfixmath")
        rf = ratio(best(d), best(f))
        rq = ratio(best(d), best(q))
        add(f"| {name} | {fmt_ns(best(d))} | {fmt_ns(best(f))} | {fmt_ns(best(q))} | "
            f"{fmt_ratio(rf)} | {fmt_ratio(rq)} | ≥ {goal:g} | {goal_status(f, rf, goal)} |")
    add("")

    add("### Per function")
    for name in [n for n, _ in FUNCTIONS] + EXTRA:
        goal = dict(FUNCTIONS).get(name)
        present = [(key, title, runs[f"{name}/{key}"]) for key, title in IMPLEMENTATIONS
                   if f"{name}/{key}" in runs]
        if not present:
            continue
        add("")
        add(f"#### {name}")
        add("")
        note = ""
        if name == "sin_wide":
            note = (" Not a goal of the issue: it shows the cost of detsim's exact range reduction "
                    "over the whole Fixed range. libfixmath cannot represent these inputs; glibc "
                    "switches to its slow reduction above about 1e8, so most double calls take it.")
        add(f"Inputs: {present[0][2]['label']}.{note}")
        add("")
        add("| implementation | ns/op (min) | ns/op (median) | calls/s (best) | vs double | goal | "
            "status | max abs err |")
        add("|---|--:|--:|--:|--:|--:|---|--:|")
        base = best(runs.get(f"{name}/double"))
        for key, title, run in present:
            r = ratio(base, best(run))
            if key == "double":
                goal_cell, status = "", ""
            elif key == "detsim" and goal is not None:
                goal_cell, status = f"≥ {goal:g}", goal_status(run, r, goal)
            elif key == "detsim":
                goal_cell = ""
                status = ("" if run["err"] <= DETSIM_SANITY_BOUND
                          else "invalid: results wrong, timing meaningless")
            else:
                goal_cell, status = "", ""
            add(f"| {title} | {fmt_ns(best(run))} | {fmt_ns(median(run))} | {fmt_rate(best(run))} | "
                f"{fmt_ratio(r)} | {goal_cell} | {status} | {fmt_err(run['err'])} |")
    add("")


# ---- The document -------------------------------------------------------------------------------


def fmt_load(values):
    return ", ".join(f"{x:.2f}" for x in values) if values else "?"


def render(sim, fixed, args):
    # The machine and build are the same for both programs; take them from whichever ran.
    context = (sim or fixed or {}).get("context", {})
    cpu = lscpu()

    lines = []
    add = lines.append
    add("# Benchmarks")
    add("")
    add("<!-- Generated by scripts/bench_report.py from the JSON of bench/sim_bench and "
        "bench/fixed_bench; do not edit by hand. -->")
    add("")
    if args.smoke:
        add("> **SMOKE RUN — these figures are not measurements.** This file was written by "
            "`scripts/bench.sh --smoke`: small scenes and a very short minimum time per benchmark, "
            "only to prove that the programs and the report work end to end. Regenerate it with "
            "the command below before quoting any number.")
        add("")
    add("Two Google Benchmark programs: `bench/sim_bench` (the shared pile scenes beside Bullet, "
        "state save/restore/hash, rollback, sleeping) and `bench/fixed_bench` (the fixed-point "
        "functions beside glibc double and libfixmath). The machine is shared and noisy: figures "
        "here are reported, never asserted. No test and no CI step fails because of them.")
    add("")
    add("Regenerate the whole file with:")
    add("")
    add("```sh")
    add(args.command)
    add("```")
    add("")

    add("## Machine and build")
    add("")
    model = cpu.get("Model name") or platform.processor() or "unknown"
    logical = cpu.get("CPU(s)") or str(context.get("num_cpus", "?"))
    per_socket = cpu.get("Core(s) per socket")
    sockets = cpu.get("Socket(s)")
    threads = cpu.get("Thread(s) per core")
    cores = logical + " logical CPUs"
    if per_socket and sockets and sockets.isdigit() and per_socket.isdigit():
        cores += f" ({int(per_socket) * int(sockets)} cores, {threads or '?'} thread(s) per core)"
    nproc = f"; `nproc` {args.nproc}" if args.nproc else ""
    add(f"- CPU: {model}; {cores}{nproc}; {context.get('mhz_per_cpu', '?')} MHz reported")
    if cpu.get("Hypervisor vendor"):
        add(f"- Virtualised: {cpu['Hypervisor vendor']} ({cpu.get('Virtualization type', '?')})")
    caches = [f"{k} {cpu[k]}" for k in ("L1d cache", "L2 cache", "L3 cache") if k in cpu]
    if caches:
        add("- Caches: " + ", ".join(caches))
    load = []
    if args.load_before:
        load.append(f"before the runs `{args.load_before}`")
    if sim:
        load.append(f"at the start of sim_bench {fmt_load(sim['context'].get('load_avg'))}")
    if fixed:
        load.append(f"at the start of fixed_bench {fmt_load(fixed['context'].get('load_avg'))}")
    if args.load_after:
        load.append(f"after the runs `{args.load_after}`")
    add("- Load (1, 5, 15-minute load averages; the machine is shared, and a load above the CPU "
        "count means other processes competed for it): " + "; ".join(load))
    banner = compiler_banner(args.compiler)
    add(f"- Compiler: {context.get('detsim_compiler', '?')}" + (f" (`{banner}`)" if banner else ""))
    add(f"- Build: {context.get('detsim_build_type', '?')}, flags `{context.get('detsim_cxx_flags', '')}` "
        "(detsim and the benchmarks; no -march). glibc, libfixmath and Bullet are the "
        "distribution's builds.")
    if sim:
        bullet = sim["context"].get("bullet_version", "")
        add("- Bullet: " + (f"{int(bullet) // 100}.{int(bullet) % 100:02d} (Debian `libbullet-dev`, "
                            "float)" if bullet.isdigit() else bullet or "?"))
    lib_type = context.get("library_build_type", "?")
    add(f"- Google Benchmark library build type: {lib_type}" +
        (" (Debian builds it without NDEBUG, so it warns; the timed code is in these programs and "
         "unaffected)" if lib_type == "debug" else ""))
    add(f"- Run date: {context.get('date', '?')}")
    if args.options:
        add(f"- Options: `{args.options}`")
    if args.run_seconds is not None:
        add(f"- `scripts/bench.sh` ran the programs for {args.run_seconds:.0f} s"
            + (f" (after {args.build_seconds:.0f} s of building)" if args.build_seconds is not None
               else ""))
    add(f"- Report written: {datetime.datetime.now(datetime.timezone.utc).isoformat(timespec='seconds')}")
    add("")

    if sim:
        render_sim(sim, args, add)
    if fixed:
        render_fixed(fixed, args, add)
    return "\n".join(lines)


def load_json(path):
    if not path:
        return None
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sim-json", help="Google Benchmark JSON output of sim_bench")
    parser.add_argument("--json", "--fixed-json", dest="fixed_json",
                        help="Google Benchmark JSON output of fixed_bench")
    parser.add_argument("--out", required=True, help="Markdown file to write")
    parser.add_argument("--command", default="scripts/bench.sh",
                        help="the command that regenerates the report, quoted in it")
    parser.add_argument("--compiler", help="path of the C++ compiler, for its --version banner")
    parser.add_argument("--options", default="", help="benchmark options used, quoted in the report")
    parser.add_argument("--nproc", default="", help="the output of nproc")
    parser.add_argument("--load-before", default="", help="uptime's output before the runs")
    parser.add_argument("--load-after", default="", help="uptime's output after the runs")
    parser.add_argument("--run-seconds", type=float, help="how long the programs ran")
    parser.add_argument("--build-seconds", type=float, help="how long building took")
    parser.add_argument("--smoke", action="store_true", help="label the report as a smoke run")
    args = parser.parse_args()
    if not args.sim_json and not args.fixed_json:
        parser.error("give --sim-json, --fixed-json or both")
    text = render(load_json(args.sim_json), load_json(args.fixed_json), args)
    with open(args.out, "w", encoding="utf-8") as f:
        f.write(text)
    print(f"wrote {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
