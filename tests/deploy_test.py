#!/usr/bin/env python3
"""The deployment files under deploy/ agree with the detsim command, and sharded bulk
verification gives the results of one process.

  deploy_test.py DETSIM SOURCE_DIR

1. Every YAML file under deploy/ parses. The Kubernetes Job is an Indexed Job with
   backoffLimitPerIndex, restartPolicy Never, --of equal to its completions, its shard index from
   JOB_COMPLETION_INDEX, and a podFailurePolicy whose exit codes are exactly the failing codes that
   `detsim verify --help` documents under "Exit status:" (results, not accidents: never retried).
   The Agones Fleet serves UDP on the port it binds, with health checking and a CPU request. Every
   --flag that the Job, the Fleet, the Slurm script and scripts/cluster-verify.sh pass exists in
   `detsim verify --help` or `detsim serve --help`.
2. A small version of scripts/cluster-verify.sh: six short replays (one with a desync, one corrupt,
   one truncated) in a manifest; the Slurm script run as 3 plain processes with
   SLURM_ARRAY_TASK_ID=0..2, and the Job's own arguments for each of its indexes (as the kubelet
   expands them, the manifest's path swapped for the test's); each merged by
   scripts/verify_shards.py, which checks that every entry has exactly one result and that the
   results equal one `--jobs 1` process's byte for byte apart from the timing keys.

Exit status: 0 passed; 1 a check failed (each failure printed).
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

try:
    import yaml
except ImportError:
    print("deploy_test: needs python3-yaml (scripts/install-deps.sh installs it)", file=sys.stderr)
    sys.exit(1)

DETSIM, SOURCE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
sys.path.insert(0, os.path.join(SOURCE, "scripts"))
import verify_shards  # noqa: E402

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
    return condition


def run(args, **kwargs):
    return subprocess.run(args, capture_output=True, text=True, timeout=60, **kwargs)


def help_flags(command):
    """The --flags a subcommand's --help lists, and the help text."""
    text = run([DETSIM, command, "--help"]).stdout
    return set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", text)), text


def exit_codes(help_text):
    """The codes of the "Exit status:" paragraph: "Exit status: 0 ...; 1 ...; 2 ..."."""
    at = help_text.find("Exit status:")
    if at < 0:
        return set()
    paragraph = re.split(r"\n\s*\n|--json prints", help_text[at:])[0]
    return {int(c) for c in re.findall(r"(?:Exit status:|;|,)\s*(\d+)\s+(?=[^\s\d])", paragraph)}


def flags_in(args):
    return [a.split("=", 1)[0] for a in args if isinstance(a, str) and a.startswith("--")]


def value_after(args, flag):
    for i, a in enumerate(args):
        if a == flag and i + 1 < len(args):
            return args[i + 1]
        if isinstance(a, str) and a.startswith(flag + "="):
            return a.split("=", 1)[1]
    return None


def containers(pod_spec):
    return (pod_spec or {}).get("containers") or []


def detsim_args(container):
    """The detsim arguments of a container of the image (entry point detsim): args, or command
    after a leading detsim."""
    command = list(container.get("command") or [])
    if command and os.path.basename(command[0]) == "detsim":
        command = command[1:]
    return [str(a) for a in command + list(container.get("args") or [])]


def shell_verify_calls(path):
    """The words of each `"$detsim" verify --...` command of a shell script (continuation lines
    joined, up to the first pipe, redirection or separator)."""
    text = open(path, encoding="utf-8").read().replace("\\\n", " ")
    calls = []
    for line in text.splitlines():
        if line.lstrip().startswith("#"):
            continue
        # The binary is a variable: "$detsim" verify ..., ${DETSIM} verify ...
        match = re.search(r"\"?\$\{?(?:detsim|DETSIM)\}?\"?\s+verify\s+(--.*)$", line)
        if not match:
            continue
        words = []
        for word in match.group(1).split():
            if word in ("|", "||", "&&", ";", ")") or word[:1] in "<>" or word[:2] in ("1>", "2>"):
                break  # the end of the command
            words.append(word.rstrip(")").strip("\"'"))
            if word.endswith(")"):
                break  # the end of a $(...) substitution
        calls.append(words)
    return calls


verify_flags, verify_help = help_flags("verify")
serve_flags, _ = help_flags("serve")
codes = exit_codes(verify_help)
check(0 in codes and len(codes) >= 2, "detsim verify --help: no 'Exit status: 0 ..., 1 ..., 2 ...' found (got %s)" % sorted(codes))
failing_codes = codes - {0}
check("--manifest" in verify_flags, "detsim verify --help has no --manifest: an old binary?")

# --- 1. the deployment files -----------------------------------------------------------------
deploy = os.path.join(SOURCE, "deploy")
documents = []
for path in sorted(glob.glob(os.path.join(deploy, "**", "*.y*ml"), recursive=True)):
    try:
        for doc in yaml.safe_load_all(open(path, encoding="utf-8")):
            if doc is not None:
                documents.append((os.path.relpath(path, SOURCE), doc))
    except yaml.YAMLError as e:
        check(False, "%s does not parse: %s" % (path, e))

jobs = [(p, d) for p, d in documents if d.get("kind") == "Job"]
fleets = [(p, d) for p, d in documents if d.get("kind") == "Fleet"]
check(len(jobs) == 1, "expected one Kubernetes Job under deploy/, found %d" % len(jobs))
check(len(fleets) == 1, "expected one Agones Fleet under deploy/, found %d" % len(fleets))

job_args = None
job_completions = None
for path, job in jobs:
    spec = job.get("spec") or {}
    check(job.get("apiVersion") == "batch/v1", "%s: apiVersion %r, not batch/v1" % (path, job.get("apiVersion")))
    check(spec.get("completionMode") == "Indexed", "%s: completionMode is not Indexed" % path)
    check(isinstance(spec.get("backoffLimitPerIndex"), int) and spec["backoffLimitPerIndex"] >= 1,
          "%s: no backoffLimitPerIndex >= 1: crashes would not be retried per index" % path)
    job_completions = spec.get("completions")
    check(isinstance(job_completions, int) and job_completions >= 1, "%s: no completions" % path)
    pod = (spec.get("template") or {}).get("spec") or {}
    check(pod.get("restartPolicy") == "Never", "%s: podFailurePolicy needs restartPolicy Never" % path)
    names = [c.get("name") for c in containers(pod)]
    check(len(names) == 1, "%s: expected one container, found %s" % (path, names))
    rules = (spec.get("podFailurePolicy") or {}).get("rules") or []
    policy_codes = set()
    for rule in rules:
        on = rule.get("onExitCodes")
        if on is None:
            continue
        check(on.get("operator") == "In", "%s: an onExitCodes rule with operator %r" % (path, on.get("operator")))
        check(on.get("containerName") in names, "%s: onExitCodes names container %r, not one of %s" % (path, on.get("containerName"), names))
        check(rule.get("action") in ("FailIndex", "FailJob"),
              "%s: exit codes %s are results: retrying gives the same, so the action must fail, not %r" % (path, on.get("values"), rule.get("action")))
        policy_codes |= set(on.get("values") or [])
    check(policy_codes == failing_codes,
          "%s: podFailurePolicy exit codes %s, detsim verify documents %s" % (path, sorted(policy_codes), sorted(failing_codes)))
    for container in containers(pod):
        args = detsim_args(container)
        check(args[:1] == ["verify"], "%s: container %s does not run detsim verify: %s" % (path, container.get("name"), args))
        for flag in flags_in(args):
            check(flag in verify_flags, "%s: passes %s, which detsim verify does not have" % (path, flag))
        shard = value_after(args, "--shard")
        env_names = [e.get("name") for e in container.get("env") or []]
        check(shard in ("$(JOB_COMPLETION_INDEX)", "auto") and "JOB_COMPLETION_INDEX" not in env_names,
              "%s: --shard %r: the index must come from JOB_COMPLETION_INDEX" % (path, shard))
        check(value_after(args, "--of") == str(job_completions),
              "%s: --of %r but completions %r" % (path, value_after(args, "--of"), job_completions))
        check("--json" in args and "--manifest" in args, "%s: verify without --manifest or --json" % path)
        job_args = args

for path, fleet in fleets:
    check(fleet.get("apiVersion") == "agones.dev/v1", "%s: apiVersion %r" % (path, fleet.get("apiVersion")))
    gs = ((fleet.get("spec") or {}).get("template") or {}).get("spec") or {}
    ports = gs.get("ports") or []
    check(len(ports) >= 1 and all(p.get("protocol") == "UDP" for p in ports), "%s: ports must be UDP: %s" % (path, ports))
    health = gs.get("health") or {}
    check(health.get("disabled") is not True and isinstance(health.get("periodSeconds"), int)
          and isinstance(health.get("failureThreshold"), int), "%s: health checking not set: %s" % (path, health))
    pod = (gs.get("template") or {}).get("spec") or {}
    check(len(containers(pod)) >= 1, "%s: no container" % path)
    for container in containers(pod):
        args = detsim_args(container)
        check(args[:1] == ["serve"], "%s: container does not run detsim serve: %s" % (path, args))
        check("--agones" in args, "%s: serve without --agones" % path)
        for flag in flags_in(args):
            check(flag in serve_flags, "%s: passes %s, which detsim serve does not have" % (path, flag))
        bind = value_after(args, "--bind") or ""
        check(any(bind.endswith(":%s" % p.get("containerPort")) for p in ports),
              "%s: --bind %r is not on a containerPort of %s" % (path, bind, ports))
        cpu = ((container.get("resources") or {}).get("requests") or {}).get("cpu")
        check(cpu is not None, "%s: no resources.requests.cpu" % path)

sbatch = os.path.join(deploy, "slurm", "verify-array.sbatch")
check(os.path.exists(sbatch), "no %s" % sbatch)
sbatch_text = open(sbatch, encoding="utf-8").read()
check(re.search(r"^#SBATCH --array=0-\d+", sbatch_text, re.M) is not None, "%s: no #SBATCH --array=0-(K-1)" % sbatch)
final = re.search(r"^final_codes=\(([\d ]+)\)", sbatch_text, re.M)
check(final is not None and {int(c) for c in final.group(1).split()} == codes,
      "%s: final_codes %s, detsim verify documents %s" % (sbatch, final and final.group(1), sorted(codes)))
for script in (sbatch, os.path.join(SOURCE, "scripts", "cluster-verify.sh")):
    calls = shell_verify_calls(script)
    check(len(calls) >= 1, "%s: no detsim verify call found" % script)
    for call in calls:
        for flag in flags_in(call):
            check(flag in verify_flags, "%s: passes %s, which detsim verify does not have" % (script, flag))
check(any("--shard" in c and value_after(c, "--shard") == "auto" for c in shell_verify_calls(sbatch)),
      "%s: not --shard auto" % sbatch)

# --- 2. the shards of a small manifest equal one process --------------------------------------
FRAMES = 240
work = tempfile.mkdtemp(prefix="detsim-deploy-test.")
try:
    replays = os.path.join(work, "replays")
    os.makedirs(replays)

    def record(name, seed, *extra):
        r = run([DETSIM, "run", "--scenario", "arena", "--players", "2", "--seed", str(seed), "--frames",
                 str(FRAMES), "--record", os.path.join(replays, name)] + list(extra))
        check(r.returncode == 0, "detsim run (%s) exited %d: %s" % (name, r.returncode, r.stderr))

    for seed in (1, 2, 3):
        record("arena-%d.replay" % seed, seed)
    record("desync.replay", 4, "--inject", "%d:1:position.y:0.001" % (FRAMES // 2))
    original = open(os.path.join(replays, "arena-1.replay"), "rb").read()
    data = bytearray(original)
    for i in range(len(data) // 2, len(data) // 2 + 16):
        data[i] ^= 0xFF
    open(os.path.join(replays, "corrupt.replay"), "wb").write(data)
    open(os.path.join(replays, "truncated.replay"), "wb").write(original[: len(original) * 6 // 10])
    names = ["arena-1.replay", "desync.replay", "corrupt.replay", "arena-2.replay", "truncated.replay", "arena-3.replay"]
    manifest = os.path.join(replays, "manifest.txt")
    with open(manifest, "w", encoding="utf-8") as f:
        f.write("# a comment, then a blank line\n\n" + "\n".join(names) + "\n")

    env = {k: v for k, v in os.environ.items()
           if k not in ("JOB_COMPLETION_INDEX", "SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "AWS_BATCH_JOB_ARRAY_INDEX")}
    # The reference: one process, one thread. Run from elsewhere: paths are the manifest's.
    single = run([DETSIM, "verify", "--manifest", manifest, "--jobs", "1", "--json"], cwd=work, env=env)
    single_path = os.path.join(work, "single.jsonl")
    open(single_path, "w", encoding="utf-8").write(single.stdout)
    check(single.returncode == 1, "verify --jobs 1 over a manifest with a desync exited %d, not 1: %s"
          % (single.returncode, single.stderr))
    results = [json.loads(l) for l in single.stdout.splitlines() if l.strip()]
    by_name = {os.path.basename(r.get("path", "")): r for r in results if "path" in r}
    for name in ("arena-1.replay", "arena-2.replay", "arena-3.replay"):
        r = by_name.get(name, {})
        check(r.get("result") == "ok" and r.get("frames") == FRAMES and r.get("first_bad_frame") is None,
              "%s: expected ok with %d frames, got %s" % (name, FRAMES, r))
    r = by_name.get("desync.replay", {})
    check(r.get("result") == "desync" and r.get("first_bad_frame") == FRAMES // 2,
          "desync.replay: expected a desync at frame %d, got %s" % (FRAMES // 2, r))
    check(by_name.get("corrupt.replay", {}).get("result") == "invalid",
          "corrupt.replay (16 bytes flipped): expected invalid, got %s" % by_name.get("corrupt.replay"))
    r = by_name.get("truncated.replay", {})
    check(r.get("result") == "incomplete" and 0 < r.get("frames", 0) < FRAMES,
          "truncated.replay (60 %% of a replay): expected incomplete, got %s" % r)
    check(results and results[-1].get("summary", {}).get("replays") == len(names),
          "the last line is not a summary of %d replays: %s" % (len(names), results[-1:]))

    def merge_and_compare(directory, count, what):
        r = run([sys.executable, os.path.join(SOURCE, "scripts", "verify_shards.py"), "--manifest", manifest,
                 "--of", str(count), directory, "--single", single_path, "--single-status", str(single.returncode)])
        check(r.returncode == 0, "%s: scripts/verify_shards.py found:\n%s%s" % (what, r.stdout, r.stderr))

    # The Slurm script, as 3 plain processes with the index variable set, at once.
    slurm_out = os.path.join(work, "slurm")
    processes = []
    for i in range(3):
        task_env = dict(env, SLURM_ARRAY_TASK_ID=str(i), SLURM_ARRAY_TASK_COUNT="3", DETSIM=DETSIM)
        processes.append(subprocess.Popen(["bash", sbatch, manifest, slurm_out], cwd=work, env=task_env,
                                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
    for i, p in enumerate(processes):
        out, err = p.communicate(timeout=60)
        status_file = os.path.join(slurm_out, "shard-%d.status" % i)
        check(os.path.exists(status_file), "Slurm script, task %d: no status file (exit %d): %s" % (i, p.returncode, err))
    merge_and_compare(slurm_out, 3, "the Slurm script as 3 processes")
    # The check can fail: a shard that lost its last result is caught.
    lost = os.path.join(work, "lost")
    shutil.copytree(slurm_out, lost)
    shard_1 = open(os.path.join(lost, "shard-1.jsonl"), encoding="utf-8").read().splitlines()
    open(os.path.join(lost, "shard-1.jsonl"), "w", encoding="utf-8").write("\n".join(shard_1[:-2] + shard_1[-1:]) + "\n")
    r = run([sys.executable, os.path.join(SOURCE, "scripts", "verify_shards.py"), "--manifest", manifest, "--of", "3", lost])
    check(r.returncode == 1 and "no result" in r.stderr,
          "scripts/verify_shards.py did not notice a lost result (exit %d): %s" % (r.returncode, r.stderr))

    # The Kubernetes Job's own arguments for each index, the manifest path swapped for the test's.
    if job_args is not None and isinstance(job_completions, int):
        job_out = os.path.join(work, "job")
        os.makedirs(job_out)
        for index in range(job_completions):
            args = [manifest if a == value_after(job_args, "--manifest") else a.replace("$(JOB_COMPLETION_INDEX)", str(index))
                    for a in job_args]
            r = run([DETSIM] + args, cwd=work, env=dict(env, JOB_COMPLETION_INDEX=str(index)))
            check(r.returncode in codes, "the Job's index %d exited %d: %s" % (index, r.returncode, r.stderr))
            open(os.path.join(job_out, "shard-%d.jsonl" % index), "w", encoding="utf-8").write(r.stdout)
            open(os.path.join(job_out, "shard-%d.status" % index), "w", encoding="utf-8").write("%d\n" % r.returncode)
        merge_and_compare(job_out, job_completions, "the Kubernetes Job's %d indexes" % job_completions)
finally:
    shutil.rmtree(work, ignore_errors=True)

for f in failures:
    print("deploy_test: FAILED: %s" % f, file=sys.stderr)
print("deploy_test: %s (%d checks failed)" % ("passed" if not failures else "FAILED", len(failures)))
sys.exit(1 if failures else 0)
