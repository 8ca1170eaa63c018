#!/usr/bin/env python3
"""`stripemux view` in a real browser (docs/live-view.md): headless Chromium loads the page against
the simulated board, waits for frames, measures the depth it draws against the depth `stripemux
stream` writes, checks that the counters advance, stops and restarts the stream with the page's
buttons, and reports the figures (received → drawn latency, frames drawn per second, host CPU).

  view_browser_test.py STRIPEMUXD STRIPEMUX SOURCE_DIR [--seconds S] [--figures FILE]

Exits 77 (skipped) with a message when Chromium cannot start here; 1 on a failed check."""

import argparse
import json
import os
import re
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from webdriver import Browser, Unavailable  # noqa: E402

SKIP = 77


def fail(message):
    print(f"FAIL: {message}")
    sys.exit(1)


def read_png_gray16(path):
    """A 16-bit greyscale, non-interlaced PNG as (width, height, rows of ints)."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path}: not a PNG")
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if (depth, colour, interlace) != (16, 0, 0):
                fail(f"{path}: not 16-bit grey without interlace")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = 2 * width
    rows, previous = [], bytearray(stride)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        kind, row = line[0], bytearray(line[1:])
        for i in range(stride):
            a = row[i - 2] if i >= 2 else 0
            b = previous[i]
            c = previous[i - 2] if i >= 2 else 0
            if kind == 1:
                row[i] = (row[i] + a) & 255
            elif kind == 2:
                row[i] = (row[i] + b) & 255
            elif kind == 3:
                row[i] = (row[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                row[i] = (row[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([row[2 * x] << 8 | row[2 * x + 1] for x in range(width)])
        previous = row
    return width, height, rows


def start_daemon(daemon, board, work, nice):
    log = open(os.path.join(work, "daemon.log"), "w")
    # Niced for the figures: the device is a board of its own in the product, not a rival for
    # this machine's cores (the simulator decodes on both). Not for the checks, which share the
    # machine with other tests.
    command = (["nice", "-n", "19"] if nice else []) + [daemon, "--board", board, "--port", "0"]
    proc = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
    for _ in range(200):
        text = open(log.name).read()
        m = re.search(r"^listening on [0-9.]+:(\d+)$", text, re.M)
        if m:
            return proc, f"127.0.0.1:{m.group(1)}"
        time.sleep(0.05)
    proc.kill()
    fail(f"stripemuxd did not start: {open(log.name).read()}")


def start_view(tool, device, seconds, summary, work):
    log = open(os.path.join(work, "view.log"), "w")
    proc = subprocess.Popen([tool, "view", "--device", device, "--port", "0", "--seconds",
                             str(seconds), "--summary", summary, "--scans",
                             os.path.join(work, "scans")],
                            stdout=log, stderr=subprocess.STDOUT)
    for _ in range(200):
        m = re.search(r"open (http://\S+) in a browser", open(log.name).read())
        if m:
            return proc, m.group(1)
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    proc.kill()
    fail(f"stripemux view did not start: {open(log.name).read()}")


def reference_depth(tool, device, work):
    """cam0's depth (metres per unit, rows) from `stripemux stream` of one frame."""
    out = os.path.join(work, "stream")
    run = subprocess.run([tool, "stream", "--device", device, "--frames", "1", "--out", out],
                         capture_output=True, text=True, timeout=300)
    if run.returncode != 0:
        fail(f"stream: exit {run.returncode}: {run.stdout}{run.stderr}")
    pngs = sorted(f for f in os.listdir(out) if f.startswith("cam0_") and f.endswith(".depth.png"))
    if not pngs:
        fail(f"stream wrote no cam0 depth: {os.listdir(out)}")
    summary = json.load(open(os.path.join(out, "summary.json")))
    unit = summary.get("depth_unit_m") or summary.get("device", {}).get("depth_unit_m") or 1e-4
    return unit, read_png_gray16(os.path.join(out, pngs[0]))


def check_depth_drawn(browser, unit, reference):
    """The page's cam0 depth against the reference at a grid of pixels, and the canvas's pixels:
    coloured where there is depth, black where there is none."""
    width, height, rows = reference
    samples = [(x, y) for y in range(24, height, 48) for x in range(24, width, 48)]
    page = browser.run("""
        const c = document.getElementById('depth-cam0');
        const px = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        return arguments[0].map(([x, y]) => {
          const o = (y * c.width + x) * 4;
          return [window.smxView.depthAt(0, x, y), px[o] + px[o + 1] + px[o + 2]];
        });""", samples)
    both = diffs = 0
    close = agree = 0
    for (x, y), (depth_m, colour) in zip(samples, page):
        ref_m = rows[y][x] * unit
        agree += (ref_m > 0) == (colour > 0)
        if ref_m > 0 and depth_m > 0:
            both += 1
            diffs += 1
            close += abs(ref_m - depth_m) < 0.005
    share_drawn = sum(1 for _, colour in page if colour > 0) / len(page)
    print(f"depth canvas: {share_drawn:.0%} of {len(page)} sampled pixels coloured; "
          f"{agree}/{len(page)} agree with stream's depth on where there is depth; "
          f"{close}/{both} within 5 mm of it")
    if share_drawn < 0.5:
        fail(f"the depth canvas shows depth at only {share_drawn:.0%} of the sampled pixels")
    if agree < 0.9 * len(page):
        fail("the canvas's coloured pixels are not where the stream has depth")
    if both < 0.5 * len(page) or close < 0.9 * both:
        fail(f"the page's depth differs from the stream's: {close}/{both} within 5 mm")


def status(browser):
    return browser.run("return window.smxView.status")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("daemon")
    parser.add_argument("tool")
    parser.add_argument("src")
    parser.add_argument("--seconds", type=float, default=0,
                        help="view this long after the checks, for the figures")
    parser.add_argument("--figures", help="write the figures to this JSON file")
    parser.add_argument("--nice", action="store_true",
                        help="run the simulated device niced, as a board of its own")
    args = parser.parse_args()

    work = tempfile.mkdtemp(prefix="smx-view-")
    daemon = view = browser = None
    try:
        daemon, device = start_daemon(args.daemon, os.path.join(args.src, "boards", "sim-turntable"), work,
                                      args.nice)
        unit, reference = reference_depth(args.tool, device, work)
        summary = os.path.join(work, "summary.json")
        view, url = start_view(args.tool, device, 600, summary, work)
        try:
            browser = Browser()
        except Unavailable as e:
            print(f"SKIP: no browser test here: {e}")
            return SKIP
        browser.open(url)
        browser.wait("return window.smxView.framesDrawn >= 6", 120, "six frames drawn")
        check_depth_drawn(browser, unit, reference)

        before = status(browser)
        try:
            browser.wait(f"""const s = window.smxView.status;
                return s.device.frames_decoded > {before['device']['frames_decoded']} &&
                       s.device.frames_sent > {before['device']['frames_sent']} &&
                       s.page.frames_drawn > {before['page']['frames_drawn']};""", 120,
                         "the counters to advance")
        except AssertionError:
            fail(f"the counters did not advance in 120 s: {before} → {status(browser)}")
        after = status(browser)
        print(f"counters advance: decoded {before['device']['frames_decoded']} → "
              f"{after['device']['frames_decoded']}, drawn {before['page']['frames_drawn']} → "
              f"{after['page']['frames_drawn']}")

        browser.click("#stop")
        browser.wait("return window.smxView.status && window.smxView.status.streaming === false",
                     20, "the stream to stop after Stop")
        time.sleep(1.5)  # a frame already on its way may still be drawn
        stopped = browser.run("return window.smxView.framesDrawn")
        time.sleep(3)
        if browser.run("return window.smxView.framesDrawn") != stopped:
            fail("frames kept coming after Stop")
        if not browser.run("return document.getElementById('start').disabled === false"):
            fail("Start is not enabled while stopped")
        browser.click("#start")
        browser.wait(f"return window.smxView.framesDrawn > {stopped}", 60,
                     "frames after Start")
        print(f"Stop held the page at {stopped} frames; Start resumed it")

        if args.seconds > 0:
            time.sleep(args.seconds)
        errors = browser.run("return window.smxView.errors")
        if errors:
            fail(f"the page reported errors: {errors}")
        browser.screenshot(os.path.join(work, "page.png"))
        browser.close()
        browser = None
        view.send_signal(signal.SIGTERM)
        if view.wait(timeout=60) != 0:
            fail(f"stripemux view exited {view.returncode}: {open(os.path.join(work, 'view.log')).read()}")
        view = None
        figures = json.load(open(summary))
        page, host = figures["page"], figures["host"]
        if page["frames_drawn"] <= 0 or page["latency_ms"]["samples"] <= 0:
            fail(f"the summary has no drawn frames: {figures}")
        print(f"figures: received → drawn {page['latency_ms']['mean']:.1f} ms mean, "
              f"{page['latency_ms']['p95']:.1f} ms p95 over {page['latency_ms']['samples']} "
              f"frames; {page['drawn_per_s']:.2f} frames drawn per second "
              f"(device sends {host['received_per_s']:.2f}); host tool CPU "
              f"{host['cpu_percent']:.1f} % of a core; {host['page_kib_per_frame']:.0f} KiB per "
              f"frame to the page")
        if args.figures:
            with open(args.figures, "w") as f:
                json.dump(figures, f, indent=2)
        print("PASS")
        return 0
    finally:
        if browser:
            browser.close()
        for proc in (view, daemon):
            if proc and proc.poll() is None:
                proc.kill()
                proc.wait()


if __name__ == "__main__":
    sys.exit(main())
