#!/usr/bin/env python3
"""Generate the example rigs boards/sim/rig_*.json (format stripemux-rig/1, docs/rig-format.md).

Run from the repository root:

    python3 tools/host/make_example_rigs.py            # (re)write boards/sim/rig_*.json
    python3 tools/host/make_example_rigs.py --check    # exit 1 if a committed file differs
    python3 tools/host/make_example_rigs.py --report   # print the geometry of each rig

Standard library only. The world frame is cam0's frame (x right, y down, z forward, metres); every
other device is placed by its centre and aimed at the target point 0.9 m in front of cam0. A
projector's roll is chosen so that the world direction it is "aligned" with (its baseline to cam0
in the one-camera rigs) appears exactly along its pattern axis `angle_deg` in the projector image;
without an alignment the device is mounted level (its x axis horizontal in the world).
tests/unit/rig_json_test.cpp (ExampleRigs.*) checks the geometry of the written files.
"""

import argparse
import math
import pathlib
import sys

FORMAT = "stripemux-rig/1"
TARGET = (0.0, 0.0, 0.9)  # aim point, on cam0's optical axis
DEPTHS = (0.6, 0.9, 1.2)  # working range along cam0's axis, for --report

CAMERA = {"width": 640, "height": 480, "f": 800.0, "dist": [-0.08, 0.05, 0.0, 0.0, 0.0]}
PROJECTOR = {"width": 1024, "height": 768, "f": 1400.0, "dist": [0.0, 0.0, 0.0, 0.0, 0.0]}
# 198 stripes of 6 px span 1188 px: the pattern fills the projector image along axes at 0, 60, 90
# and 120 deg (narrower stripes would leave its ends black). At the target a stripe is 4.4-5.1 cam0
# pixels wide (--report), comfortably above the ~3 px a decoder needs.
STRIPE_PX = 6.0

# The one-camera rigs: each projector sits 0.38 m from cam0 in the image plane along the
# direction of its pattern axis, 0.10 m behind it. A 0.38 m baseline seen from 0.6-1.2 m gives
# triangulation angles of 16-28 deg; the set-back narrows the spread between near and far.
ONE_CAM_BASELINE_M = 0.38
ONE_CAM_SETBACK_M = 0.10


def around_cam0(angle_deg):
    a = math.radians(angle_deg)
    b = ONE_CAM_BASELINE_M
    return (b * math.cos(a), b * math.sin(a), -ONE_CAM_SETBACK_M)


# With a second camera every projector must triangulate with both cameras inside 15-30 deg, which
# leaves no room for each axis to lie along both of its baselines. The two-camera layouts trade
# some sensitivity (|cos| between pattern axis and epipolar direction, >= 0.45 everywhere) for
# keeping every pair inside the angle range; --report prints the numbers.
#
# Cameras: (id, centre). Projectors: (id, centre, angle_deg, camera whose baseline the pattern
# axis is aligned with, or None for level mounting). Centres in metres in cam0's frame.
RIGS = {
    "rig_2proj_1cam.json": {
        "cameras": [("cam0", (0.0, 0.0, 0.0))],
        "projectors": [
            ("proj0", around_cam0(0.0), 0.0, "cam0"),  # right of cam0
            ("proj1", around_cam0(-90.0), 90.0, "cam0"),  # above cam0 (y is down)
        ],
    },
    "rig_2proj_2cam.json": {
        # cam1 0.25 m left of cam0; the projectors above and below the camera pair, diagonal
        # patterns, so each pattern axis is within ~60 deg of both of its baselines.
        "cameras": [("cam0", (0.0, 0.0, 0.0)), ("cam1", (-0.25, 0.0, 0.0))],
        "projectors": [
            ("proj0", (-0.225, -0.415, -0.25), 45.0, None),
            ("proj1", (-0.225, 0.415, -0.25), 135.0, None),
        ],
    },
    "rig_3proj_1cam.json": {
        "cameras": [("cam0", (0.0, 0.0, 0.0))],
        "projectors": [
            ("proj0", around_cam0(0.0), 0.0, "cam0"),  # right
            ("proj1", around_cam0(60.0), 60.0, "cam0"),  # below right
            ("proj2", around_cam0(120.0), 120.0, "cam0"),  # below left
        ],
    },
    "rig_3proj_2cam.json": {
        # cam1 0.35 m right of cam0; two projectors above, one below (found by a search for the
        # best worst-case sensitivity with every pair inside 16-29 deg, then rounded to 5 mm).
        "cameras": [("cam0", (0.0, 0.0, 0.0)), ("cam1", (0.35, 0.0, 0.0))],
        "projectors": [
            ("proj0", (0.235, -0.39, -0.235), 60.0, None),
            ("proj1", (0.175, -0.31, -0.045), 120.0, None),
            ("proj2", (0.215, 0.365, -0.165), 0.0, None),
        ],
    },
}


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def scale(a, s):
    return tuple(x * s for x in a)


def unit(a):
    return scale(a, 1.0 / math.sqrt(dot(a, a)))


def look_at(centre, angle_deg=0.0, align=None):
    """Rows of R (device x, y, z in world coordinates) for a device at centre aimed at TARGET."""
    z = unit(sub(TARGET, centre))
    level_x = unit(cross((0.0, 1.0, 0.0), z))  # level mounting: x horizontal
    if align is None:
        x = level_x
    else:
        # v: the aligned direction as seen at the principal point; it must appear at angle_deg.
        v = unit(sub(align, scale(z, dot(align, z))))
        w = cross(z, v)
        a = math.radians(angle_deg)
        x = unit(tuple(math.cos(a) * vi - math.sin(a) * wi for vi, wi in zip(v, w)))
        if dot(x, level_x) < 0:  # the axis is a line: take the sign that keeps it upright
            x = scale(x, -1.0)
    y = cross(z, x)
    return (x, y, z)


def model(spec, centre, rows):
    w, h, f = spec["width"], spec["height"], spec["f"]
    R = [c for row in rows for c in row]
    t = [-dot(row, centre) for row in rows]
    K = [f, 0.0, (w - 1) / 2.0, 0.0, f, (h - 1) / 2.0, 0.0, 0.0, 1.0]
    return {"width": w, "height": h, "K": K, "dist": list(spec["dist"]), "R": R, "t": t}


def build(layout):
    cams = {cid: c for cid, c in layout["cameras"]}
    rig = {"cameras": [], "projectors": []}
    for cid, centre in layout["cameras"]:
        dev = {"id": cid, **model(CAMERA, centre, look_at(centre)), "centre": centre}
        rig["cameras"].append(dev)
    for pid, centre, angle, align_cam in layout["projectors"]:
        align = sub(centre, cams[align_cam]) if align_cam else None
        rows = look_at(centre, angle, align)
        dev = {"id": pid, **model(PROJECTOR, centre, rows), "centre": centre}
        dev["pattern"] = {"angle_deg": angle, "stripe_px": STRIPE_PX, "offset_px": 0.0}
        rig["projectors"].append(dev)
    return rig


def num(x):
    # repr() is the shortest text that reads back to the same double; snap rounding dust to 0.
    if abs(x) < 1e-15:
        x = 0.0
    if x == int(x) and abs(x) < 1e15:
        return str(int(x))
    return repr(x)


def nums(xs):
    return "[" + ", ".join(num(x) for x in xs) + "]"


def device_json(dev):
    lines = [
        f'"id": "{dev["id"]}"',
        f'"width": {dev["width"]}',
        f'"height": {dev["height"]}',
        f'"K": {nums(dev["K"])}',
        f'"dist": {nums(dev["dist"])}',
        f'"R": {nums(dev["R"])}',
        f'"t": {nums(dev["t"])}',
    ]
    if "pattern" in dev:
        p = dev["pattern"]
        lines.append(f'"pattern": {{"angle_deg": {num(p["angle_deg"])}, '
                     f'"stripe_px": {num(p["stripe_px"])}, '
                     f'"offset_px": {num(p["offset_px"])}}}')
    return "    {\n      " + ",\n      ".join(lines) + "\n    }"


def to_json(rig):
    parts = [f'  "format": "{FORMAT}"']
    for key in ("cameras", "projectors"):
        parts.append(f'  "{key}": [\n' + ",\n".join(device_json(d) for d in rig[key]) + "\n  ]")
    return "{\n" + ",\n".join(parts) + "\n}\n"


# --- report: the numbers the layouts were chosen by ---


def project(dev, X):
    xc = [dot(dev["R"][3 * i:3 * i + 3], X) + dev["t"][i] for i in range(3)]
    x, y = xc[0] / xc[2], xc[1] / xc[2]
    k1, k2, p1, p2, k3 = dev["dist"]
    r2 = x * x + y * y
    radial = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    K = dev["K"]
    return (K[0] * xd + K[2], K[4] * yd + K[5])


def pixel_ray(dev, u, v):
    """World direction through pixel (u, v) of a device without distortion."""
    K = dev["K"]
    d = ((u - K[2]) / K[0], (v - K[5]) / K[4], 1.0)
    R = dev["R"]
    return tuple(R[i] * d[0] + R[3 + i] * d[1] + R[6 + i] * d[2] for i in range(3))


def cam0_px_per_projector_px(cam0, proj):
    """How many cam0 pixels one projector pixel along the pattern axis spans at the target, on the
    plane through the target facing cam0."""
    assert not any(proj["dist"]), "pixel_ray() ignores distortion"
    centre = project(proj, TARGET)
    a = math.radians(proj["pattern"]["angle_deg"])
    seen = []
    for step in (-1.0, 1.0):
        ray = pixel_ray(proj, centre[0] + step * math.cos(a), centre[1] + step * math.sin(a))
        s = (TARGET[2] - proj["centre"][2]) / ray[2]
        seen.append(project(cam0, tuple(c + s * r for c, r in zip(proj["centre"], ray))))
    return math.dist(seen[0], seen[1]) / 2


def angle_between(a, b):
    return math.degrees(math.acos(max(-1.0, min(1.0, dot(unit(a), unit(b))))))


def report(name, rig):
    print(name)
    for proj in rig["projectors"]:
        px = cam0_px_per_projector_px(rig["cameras"][0], proj) * proj["pattern"]["stripe_px"]
        print(f"  {proj['id']}: axis {proj['pattern']['angle_deg']} deg, stripe "
              f"{proj['pattern']['stripe_px']} px = {px:.2f} cam0 px at the target")
    for cam in rig["cameras"]:
        for proj in rig["projectors"]:
            tri = [angle_between(sub(cam["centre"], (0, 0, d)), sub(proj["centre"], (0, 0, d)))
                   for d in DEPTHS]
            # Epipolar direction in the projector image: two points on the camera's ray through the
            # target, projected into the projector.
            ray = sub(TARGET, cam["centre"])
            u0 = project(proj, tuple(c + 0.95 * r for c, r in zip(cam["centre"], ray)))
            u1 = project(proj, tuple(c + 1.05 * r for c, r in zip(cam["centre"], ray)))
            a = math.radians(proj["pattern"]["angle_deg"])
            sens = abs(dot(unit(sub(u1, u0)), (math.cos(a), math.sin(a))))
            dist = math.dist(cam["centre"], proj["centre"])
            angles = ", ".join(f"{t:.1f}" for t in tri)
            print(f"  {cam['id']}-{proj['id']}: baseline {dist:.3f} m, triangulation {angles} deg "
                  f"at {DEPTHS} m, |cos(axis, epipolar)| {sens:.2f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default_out = pathlib.Path(__file__).resolve().parents[2] / "boards" / "sim"
    parser.add_argument("--out", type=pathlib.Path, default=default_out)
    parser.add_argument("--check", action="store_true", help="compare instead of writing")
    parser.add_argument("--report", action="store_true", help="print each rig's geometry")
    args = parser.parse_args()
    stale = []
    for name, layout in RIGS.items():
        rig = build(layout)
        text = to_json(rig)
        path = args.out / name
        if args.report:
            report(name, rig)
        if args.check:
            if not path.exists() or path.read_text() != text:
                stale.append(str(path))
        elif not args.report:
            path.write_text(text)
            print(f"wrote {path}")
    if stale:
        print("out of date (run tools/host/make_example_rigs.py): " + ", ".join(stale),
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
