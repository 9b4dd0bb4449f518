#!/usr/bin/env python3
"""`detsim view` pages, rendered by headless Chromium.

  viewer_test.py DETSIM [CHROMIUM]

1. A 600-frame 4-player arena replay becomes one page that needs nothing from elsewhere (no
   src= or href= to another file or host). Chromium opens it at frame 0 and at frame 480 (the
   page's "#frame=N&probe" fragment): the page says it is ready, shows the frame asked for, and
   shows as that frame's hash the one `detsim seek` computes for it. From the two screenshots:
   around every body whose drawn position moved by more than 12 pixels between the two frames
   (the page's probe gives each body's place on the drawing), pixels changed; on the background far
   from every body and from the page's panels, no pixel changed (the camera is the same).
2. Two records of one match, the second with one body's velocity changed at frame 400 (run
   --inject): before frame 400 no body is marked; after the first keyframe that holds the
   change (600), that body is marked as differing, and the page says where the records diverge.
3. A desync report: its frames are shown up to its last.
4. Bad input: a missing record, two records of different matches and a range past the end are
   refused with exit status 2 and a message naming the problem, and write no page.
5. An hour of 8-player arena (216,000 frames; DETSIM_TEST_SCALE=N shows 1/N of it, for sanitizer
   builds) gives a page of at most 20 MB (issue 23's bound; 20/N MB beside the page's fixed part
   for a scaled run), which opens at its first and its last frame.

Exit status: 0 passed; 1 a check failed (each failure printed); 77 (skipped) without Chromium.
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

DETSIM = os.path.abspath(sys.argv[1])
CHROMIUM = sys.argv[2] if len(sys.argv) > 2 else (shutil.which("chromium") or "")
SCALE = max(1, int(os.environ.get("DETSIM_TEST_SCALE", "1")))
WIDTH, HEIGHT = 900, 640
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL: " + what, file=sys.stderr)
    return ok


def run(*args, expect=0):
    p = subprocess.run([DETSIM, *args], capture_output=True, text=True)
    if p.returncode != expect:
        raise SystemExit(f"detsim {' '.join(args)}: exit {p.returncode} (expected {expect})\n"
                         f"{p.stdout}{p.stderr}")
    return p


def browser(page, fragment, screenshot=None):
    """Opens page#fragment in headless Chromium; returns the DOM after the page's scripts ran."""
    args = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu-sandbox",
            "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--hide-scrollbars",
            f"--window-size={WIDTH},{HEIGHT}", "--virtual-time-budget=20000"]
    args.append(f"--screenshot={screenshot}" if screenshot else "--dump-dom")
    args.append("file://" + os.path.abspath(page) + "#" + fragment + f"&size={WIDTH}x{HEIGHT}")
    p = subprocess.run(args, capture_output=True, text=True, timeout=180)
    if p.returncode != 0:
        raise SystemExit(f"chromium failed ({p.returncode}): {p.stderr[-2000:]}")
    return p.stdout


def probe(page, frame):
    dom = browser(page, f"frame={frame}&probe")
    ready = re.search(r'data-ready="([a-z]+)"', dom)
    check(ready is not None and ready.group(1) == "yes",
          f"{page} at frame {frame}: the page is not ready ({ready.group(1) if ready else 'no flag'})")
    m = re.search(r'<pre id="detsim-probe"[^>]*>(\{.*?)</pre>', dom, re.S)
    if not check(m is not None, f"{page} at frame {frame}: no probe in the page"):
        return {"frame": None, "hash": None, "bodies": []}
    return json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))


def read_png(path):
    """RGB(A) rows of a PNG (8-bit, colour type 2 or 6), with the filters undone."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    at, idat, width, height, channels = 8, b"", 0, 0, 0
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), (depth, colour)
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - channels] if x >= channels else 0
            b = prev[x]
            c = prev[x - channels] if x >= channels else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return width, height, channels, rows


def pixel(img, x, y):
    width, height, channels, rows = img
    x, y = min(max(x, 0), width - 1), min(max(y, 0), height - 1)
    return rows[y][x * channels:x * channels + 3]


def changed_near(a, b, x, y, r=4):
    return any(pixel(a, x + dx, y + dy) != pixel(b, x + dx, y + dy)
               for dx in range(-r, r + 1) for dy in range(-r, r + 1))


def main():
    if not CHROMIUM or not os.path.exists(CHROMIUM):
        print("viewer_test: no chromium (Debian: apt-get install chromium): skipped", file=sys.stderr)
        return 77
    tmp = tempfile.mkdtemp(prefix="detsim-viewer-")
    os.chdir(tmp)

    # 1. One replay, two frames.
    run("run", "--scenario", "arena", "--players", "4", "--frames", "600", "--record", "a.dsr")
    out = json.loads(run("view", "a.dsr", "--json").stdout)
    check(out["page"] == "a.html" and os.path.exists("a.html"), f"default page name: {out}")
    check(out["frames"] == 601 and out["first"] == 0 and out["last"] == 600, f"frames: {out}")
    html = open("a.html", encoding="utf-8").read()
    check(len(html.encode()) == out["bytes"], "the page's size is what --json says")
    outside = re.findall(r'(?:src|href)\s*=\s*["\'][^"\']+', html)
    check(not outside, f"the page refers to other files or hosts: {outside[:3]}")
    shots, probes = {}, {}
    for frame in (0, 480):
        probes[frame] = probe("a.html", frame)
        check(probes[frame]["frame"] == frame, f"asked for frame {frame}, shown {probes[frame]['frame']}")
        seek = json.loads(run("seek", "a.dsr", str(frame), "--json").stdout)
        check(probes[frame]["hash"] == seek["hash"],
              f"frame {frame}: page hash {probes[frame]['hash']}, detsim seek {seek['hash']}")
        browser("a.html", f"frame={frame}", screenshot=f"a{frame}.png")
        shots[frame] = read_png(f"a{frame}.png")
    # The drawing fills the window: its fractions are the screenshot's pixels.
    def px(b):
        return [round(b["screen"][0] * WIDTH), round(b["screen"][1] * HEIGHT)]
    at0 = {b["id"]: px(b) for b in probes[0]["bodies"]}
    at1 = {b["id"]: px(b) for b in probes[480]["bodies"]}
    moved = [i for i in at0 if i in at1 and
             abs(at0[i][0] - at1[i][0]) + abs(at0[i][1] - at1[i][1]) > 12 and
             all(0 <= v[0] < WIDTH and 80 <= v[1] < HEIGHT - 60 for v in (at0[i], at1[i]))]
    check(len(moved) >= 2, f"at least two bodies move on screen between frames 0 and 480 ({moved})")
    for i in moved:
        for x, y in (at0[i], at1[i]):
            check(changed_near(shots[0], shots[480], x, y),
                  f"body {i} moved from {at0[i]} to {at1[i]}: no pixel changed near ({x}, {y})")
    # The background: the first row under the top panels' height and the last above the bar, away
    # from every body at either frame.
    bodies = list(at0.values()) + list(at1.values())
    quiet = [(x, y) for y in (HEIGHT - 70, 300) for x in range(20, WIDTH - 20, 40)
             if all(abs(x - b[0]) + abs(y - b[1]) > 120 for b in bodies)]
    check(len(quiet) >= 3, f"background points to compare ({quiet})")
    same = [p for p in quiet if pixel(shots[0], *p) == pixel(shots[480], *p)]
    check(len(same) == len(quiet), f"background changed at {sorted(set(quiet) - set(same))}")

    # 2. Two records of one match, one changed at frame 400.
    run("run", "--scenario", "arena", "--players", "4", "--frames", "600", "--record", "b.dsr",
        "--inject", "400:7:linear_velocity.x:2")
    out = json.loads(run("view", "a.dsr", "b.dsr", "-o", "ab.html", "--json").stdout)
    check(out["outcome"] == "diverged" and out["first_divergent_frame"] == 400, f"overlay: {out}")
    before, after = probe("ab.html", 399), probe("ab.html", 600)
    check(not any(b["red"] for b in before["bodies"]), f"frame 399: a body is marked {before}")
    red = sorted(b["id"] for b in after["bodies"] if b["red"])
    check(7 in red, f"frame 600: body 7 is not marked as differing (marked: {red})")
    dom = browser("ab.html", "frame=600")
    check("diverged at frame 400" in dom, "the overlay page does not say where the records diverge")

    # 3. A desync report (this machine's state at frame 450 of b.dsr).
    run("verify", "b.dsr", "--report", "b.dsd", "--at", "450", expect=1)
    out = json.loads(run("view", "b.dsd", "--json").stdout)
    check(out["last"] == 450 and out["page"] == "b.html", f"report page: {out}")
    check(probe("b.html", 450)["frame"] == 450, "the report's last frame is shown")

    # 4. Bad input: exit 2, a message, no page.
    for args, says in ((["missing.dsr", "-o", "bad.html"], "missing.dsr"),
                       (["a.dsr", "--to", "601", "-o", "bad.html"], "601"),
                       (["a.dsr", "--from", "500", "--to", "400", "-o", "bad.html"], "500")):
        p = run("view", *args, expect=2)
        check(says in p.stderr, f"view {args}: the message does not name {says}: {p.stderr}")
    run("run", "--scenario", "arena", "--players", "2", "--frames", "60", "--record", "c.dsr")
    p = run("view", "a.dsr", "c.dsr", "-o", "bad.html", expect=2)
    check("not records of the same match" in p.stderr and "players" in p.stderr,
          f"different matches: {p.stderr}")
    check(not os.path.exists("bad.html"), "a refused view wrote a page")

    # 5. An hour of 8 players (1/SCALE of it).
    frames = 216000 // SCALE
    run("run", "--scenario", "arena", "--players", "8", "--frames", str(frames), "--record",
        "hour.dsr")
    out = json.loads(run("view", "hour.dsr", "--json").stdout)
    fixed = len(html.encode()) - len(re.search(
        r'id="detsim-chunks">(.*?)</script>', html, re.S).group(1))
    limit = 20_000_000 if SCALE == 1 else fixed + (20_000_000 - fixed) // SCALE
    check(out["bytes"] <= limit, f"{frames} frames of 8-player arena: {out['bytes']} bytes > {limit}")
    print(f"viewer_test: {frames} frames of 8-player arena: {out['bytes'] / 1e6:.1f} MB "
          f"(limit {limit / 1e6:.1f} MB), written in {out['seconds']:.1f} s")
    for frame in (0, frames):
        check(probe("hour.html", frame)["frame"] == frame, f"hour page: frame {frame} is shown")

    shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print(f"viewer_test: {len(failures)} check(s) failed", file=sys.stderr)
        return 1
    print("viewer_test: passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
