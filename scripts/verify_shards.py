#!/usr/bin/env python3
"""Merges the outputs of `detsim verify --manifest LIST --shard I --of K --json` (K shards) and
checks them.

Shard I verifies the entries whose index mod K is I, in entry order, so entry i is line i // K
of shard i mod K: the merge puts every result back in entry order. It checks that every manifest
entry has exactly one result, with the entry's path; that each shard's summary line adds up its
own lines; and, given the output of one process over the whole manifest (--single), that the merged
lines equal its lines byte for byte once the timing keys are removed, the summed summaries equal its
summary, and the shards' exit statuses combine to its exit status (1 if any shard found a desync,
else 2 if any found an invalid replay, else 0).

  verify_shards.py --manifest LIST --of K DIR [--single FILE [--single-status N]] [--output FILE]

DIR holds shard-I.jsonl for I in 0 .. K-1, and optionally shard-I.status (the exit status), as
deploy/slurm/verify-array.sbatch writes them. --output writes the merged lines, in entry order,
and one summary line over all shards: the counts, "game_seconds", "seconds" (the sum of the
shards'), "entries" and "shards".

Exit status: 0 every check passed; 1 a check failed (each failure is printed); 2 bad usage or a
missing file. Also usable as a module (tests/deploy_test.py).
"""
import argparse
import json
import os
import re
import sys

# Keys whose values depend on the machine's speed, not on the replay: removed before comparing.
TIMING_KEYS = ("seconds", "replay_seconds", "frames_per_second", "realtime_factor")
SUMMARY_COUNTS = ("replays", "ok", "desync", "invalid", "incomplete", "frames")
OPTIONAL_SUMS = ("game_seconds",)  # summed when the shards' summaries have them
_NUMBER = r"-?[0-9]+(?:\.[0-9]*)?(?:[eE][-+]?[0-9]+)?"
_TIMING = re.compile(r'"(?:%s)":(?:%s|null)' % ("|".join(TIMING_KEYS), _NUMBER))


def without_timing(line):
    """The line's text with every timing key and its value removed, and nothing else changed."""
    text = _TIMING.sub("", line.rstrip("\n"))
    text = re.sub(r",(?=,)", "", text)  # a removed key between two others
    text = text.replace("{,", "{").replace(",}", "}")
    return text


def manifest_entries(path):
    """The manifest's entries as `detsim verify --manifest` reads them: one per line, blank lines
    and lines starting with '#' skipped, relative paths relative to the manifest's directory.
    Returns (entry as written, the path it names) pairs."""
    base = os.path.dirname(os.path.abspath(path))
    entries = []
    with open(path, encoding="utf-8") as f:
        for raw in f:
            line = raw.rstrip("\r\n")
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            entries.append((line, os.path.normpath(os.path.join(base, line))))
    return entries


def names_entry(result_path, entry, manifest_dir):
    """Whether a result's "path" names this manifest entry: as written, as resolved, or the same
    file."""
    written, resolved = entry
    if result_path in (written, resolved) or os.path.normpath(result_path) == resolved:
        return True
    for candidate in (result_path, os.path.join(manifest_dir, result_path)):
        if os.path.exists(candidate) and os.path.exists(resolved):
            if os.path.samefile(candidate, resolved):
                return True
    return False


class Shard:
    """One shard's output: its per-replay lines and its summary."""

    def __init__(self, index, lines, status=None):
        self.index = index
        self.status = status
        self.results = []  # (raw line, parsed object)
        self.summary = None
        self.problems = []
        for number, line in enumerate(lines, 1):
            if not line.strip():
                continue
            try:
                obj = json.loads(line)
            except ValueError as e:
                self.problems.append("shard %d line %d is not JSON (%s): %s" % (index, number, e, line[:120]))
                continue
            if "summary" in obj:
                if self.summary is not None:
                    self.problems.append("shard %d has two summary lines" % index)
                self.summary = obj["summary"]
            elif self.summary is not None:
                self.problems.append("shard %d line %d comes after its summary line" % (index, number))
            else:
                self.results.append((line.rstrip("\n"), obj))
        if self.summary is None:
            self.problems.append("shard %d has no summary line (did it finish?)" % index)


def read_lines(path):
    with open(path, encoding="utf-8") as f:
        return f.read().splitlines()


def combined_status(statuses):
    """The exit status one process over all the entries gives: 1 if any desync, else 2 if any
    invalid, else 0; None if a status is unknown or not a result (a crash)."""
    if any(s not in (0, 1, 2) for s in statuses):
        return None
    if 1 in statuses:
        return 1
    return 2 if 2 in statuses else 0


def merge(manifest, shards):
    """Puts the shards' results back in entry order. Returns (merged [(line, obj)], summary dict,
    problems [str])."""
    entries = manifest_entries(manifest)
    manifest_dir = os.path.dirname(os.path.abspath(manifest))
    count = len(shards)
    problems = [p for s in shards for p in s.problems]
    for s in shards:
        expected = len(range(s.index, len(entries), count))
        if len(s.results) != expected:
            problems.append("shard %d of %d has %d results, its share of the %d entries is %d"
                            % (s.index, count, len(s.results), len(entries), expected))
    merged = []
    for i, entry in enumerate(entries):
        shard = shards[i % count]
        position = i // count
        if position >= len(shard.results):
            problems.append("entry %d (%s): no result" % (i, entry[0]))
            continue
        line, obj = shard.results[position]
        if "index" in obj and obj["index"] != i:
            problems.append("entry %d (%s): shard %d's result %d has index %r"
                            % (i, entry[0], shard.index, position, obj["index"]))
        path = obj.get("path")
        if not isinstance(path, str) or not names_entry(path, entry, manifest_dir):
            problems.append("entry %d (%s): shard %d's result %d is for %r"
                            % (i, entry[0], shard.index, position, path))
        merged.append((line, obj))
    summary = {key: 0 for key in SUMMARY_COUNTS}
    summary["seconds"] = 0.0
    for s in shards:
        if s.summary is None:
            continue
        if "entries" in s.summary and s.summary["entries"] != len(entries):
            problems.append("shard %d counts %r entries, the manifest has %d"
                            % (s.index, s.summary["entries"], len(entries)))
        if "shards" in s.summary and s.summary["shards"] != count:
            problems.append("shard %d ran as one of %r shards, not %d" % (s.index, s.summary["shards"], count))
        if "shard" in s.summary and s.summary["shard"] != s.index:
            problems.append("shard-%d's output says it is shard %r" % (s.index, s.summary["shard"]))
        own = {key: 0 for key in SUMMARY_COUNTS}
        for _, obj in s.results:
            own["replays"] += 1
            own["frames"] += int(obj.get("frames") or 0)
            if obj.get("result") in own:
                own[obj["result"]] += 1
        for key in SUMMARY_COUNTS:
            if s.summary.get(key) != own[key]:
                problems.append("shard %d's summary says %s %r, its lines add up to %r"
                                % (s.index, key, s.summary.get(key), own[key]))
            summary[key] += int(s.summary.get(key) or 0)
        summary["seconds"] += float(s.summary.get("seconds") or 0)
        for key in OPTIONAL_SUMS:
            if key in s.summary:
                summary[key] = summary.get(key, 0) + s.summary[key]
    summary["seconds"] = round(summary["seconds"], 6)
    return merged, summary, problems


def compare_with_single(merged, summary, single_lines):
    """Differences between the merged shards and one process's output, timing keys aside."""
    problems = []
    single = Shard(-1, single_lines)
    problems += [p.replace("shard -1", "the single run") for p in single.problems]
    if len(single.results) != len(merged):
        problems.append("the single run has %d results, the shards %d" % (len(single.results), len(merged)))
    for i, ((line, _), (single_line, _)) in enumerate(zip(merged, single.results)):
        if without_timing(line) != without_timing(single_line):
            problems.append("entry %d differs:\n  shards: %s\n  single: %s" % (i, line, single_line))
    if single.summary is not None:
        for key in SUMMARY_COUNTS + tuple(k for k in OPTIONAL_SUMS if k in summary):
            if single.summary.get(key) != summary[key]:
                problems.append("summary %s: shards %r, single run %r" % (key, summary[key], single.summary.get(key)))
    return problems


def load_shards(directory, count):
    shards = []
    for i in range(count):
        path = os.path.join(directory, "shard-%d.jsonl" % i)
        if not os.path.exists(path):
            raise FileNotFoundError("%s: missing (did shard %d run?)" % (path, i))
        status = None
        status_path = os.path.join(directory, "shard-%d.status" % i)
        if os.path.exists(status_path):
            status = int(open(status_path, encoding="utf-8").read().strip())
        shards.append(Shard(i, read_lines(path), status))
    return shards


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("directory", metavar="DIR", help="the folder of shard-I.jsonl files")
    parser.add_argument("--manifest", required=True, metavar="LIST", help="the manifest the shards verified")
    parser.add_argument("--of", type=int, required=True, metavar="K", help="the number of shards")
    parser.add_argument("--single", metavar="FILE", help="the --json output of one process over the whole manifest")
    parser.add_argument("--single-status", type=int, metavar="N", help="that process's exit status")
    parser.add_argument("--output", metavar="FILE", help="write the merged lines here, in entry order")
    args = parser.parse_args(argv)
    if args.of < 1:
        parser.error("--of must be at least 1")
    try:
        shards = load_shards(args.directory, args.of)
        single_lines = read_lines(args.single) if args.single else None
    except (OSError, ValueError) as e:
        print("verify_shards: %s" % e, file=sys.stderr)
        return 2
    merged, summary, coverage = merge(args.manifest, shards)
    differences = []
    if single_lines is not None:
        differences = compare_with_single(merged, summary, single_lines)
    statuses = [s.status for s in shards]
    if args.single_status is not None and None not in statuses:
        if combined_status(statuses) != args.single_status:
            differences.append("shard exit statuses %s combine to %s, the single run exited %d"
                               % (statuses, combined_status(statuses), args.single_status))
    if args.output:
        with open(args.output, "w", encoding="utf-8") as f:
            for line, _ in merged:
                f.write(line + "\n")
            merged_summary = dict(summary, entries=len(merged), shards=args.of)
            f.write(json.dumps({"summary": merged_summary}, separators=(",", ":")) + "\n")
    problems = coverage + differences
    for p in problems:
        print("verify_shards: %s" % p, file=sys.stderr)
    counts = ", ".join("%s %d" % (k, summary[k]) for k in SUMMARY_COUNTS)
    message = "merged %d shards: %s; every entry exactly once: %s" % (args.of, counts, "no" if coverage else "yes")
    if single_lines is not None:
        message += "; equal to the single run apart from %s: %s" % (
            "/".join(TIMING_KEYS), "no" if differences else "yes")
    print(message)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
