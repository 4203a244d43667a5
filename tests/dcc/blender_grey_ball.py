#!/usr/bin/env python3
"""Dcc.BlenderGreyBall: a skyfarm sky as Blender's World is oriented and in
physical units.

Starts skyfarm-server (one local worker) on free ports, then for a morning
and an afternoon sun over Paris (and the afternoon again with the sun as a
Sun lamp, --sun lamp) runs headless Blender with
scripts/blender/skyfarm_world.py (the World from GET /v1/sky/envmap.exr)
and grey_ball_scene.py (a grey ball under an orthographic camera looking
down, rendered with Cycles, measured), and checks:

  orientation  the luminance-weighted centroid of the ball's pixels points to
               the sun's azimuth in Blender's frame (north = +Y, east = +X:
               angle from +X = 90 deg - azimuth) within 20 deg: the side
               facing the sun is the brightest; the sky's own gradient and
               the map's 1.4 deg pixels move it by a few degrees only
  brightness   the ball's top (normal up) is a Lambertian surface under the
               whole upper hemisphere: L = albedo / pi x E_h.  With the
               World strength 1/683 the pixel is in W m^-2 sr^-1, so
               683 x pixel = albedo / pi x E_h (lux), E_h integrated from
               the map in Blender (sun included).  Tolerance 10 %: Monte
               Carlo noise of 16 pixels x 32 samples (0.8 % in the worst run seen), the
               map's bilinear filtering of the sun's pixel (energy kept to
               < 1 %) and the 4 deg spread of the pixels' normals (< 0.3 %)
  exposure     the script's exposure shows the albedo-0.5 top at scene value
               0.5 (an 18 % card at 0.18), within the same 10 %

usage: blender_grey_ball.py --server BIN --worker BIN --source DIR [--blender BIN]
Exits 77 (skipped) when Blender is not installed (scripts/install-deps.sh --dcc).
"""
import argparse
import json
import math
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.parse
import urllib.request

PLACE = {"lat": 48.85, "lon": 2.35}
CASES = [  # (name, time, sun): the sun's azimuth comes from the server
    ("morning", "2026-06-21T08:00:00+02:00", "disk"),
    ("afternoon", "2026-06-21T17:00:00+02:00", "disk"),
    ("afternoon-lamp", "2026-06-21T17:00:00+02:00", "lamp"),
]
WIDTH = 256
ORIENTATION_TOLERANCE_DEG = 20.0
BRIGHTNESS_TOLERANCE = 0.10
LUMINOUS_EFFICACY = 683.0


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def angle_difference(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--server", required=True)
    p.add_argument("--worker", required=True)
    p.add_argument("--source", required=True)
    p.add_argument("--blender", default="")
    args = p.parse_args()
    blender = args.blender if args.blender and not args.blender.endswith("NOTFOUND") else shutil.which("blender")
    if not blender or not os.path.exists(blender):
        print("Dcc.BlenderGreyBall: blender is not installed (scripts/install-deps.sh --dcc)")
        return 77

    work = tempfile.mkdtemp(prefix="skyfarm-dcc-")
    http, broker = free_port(), free_port()
    env = {k: v for k, v in os.environ.items() if not k.startswith("SKYFARM_")}
    server = subprocess.Popen([args.server, "--listen", f"127.0.0.1:{http}", "--broker", f"tcp://127.0.0.1:{broker}",
                               "--local-workers", "1", "--worker-binary", args.worker,
                               "--data-dir", os.path.join(work, "data")],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env)
    base = f"http://127.0.0.1:{http}"
    failures = []
    try:
        for name, when, sun_as in CASES:
            # The sun's position, from the same service (also waits for the server to listen).
            query = urllib.parse.urlencode({**PLACE, "time": when, "view_zenith": 0, "view_azimuth": 0})
            deadline = time.monotonic() + 30
            while True:
                try:
                    with urllib.request.urlopen(f"{base}/v1/sky?{query}", timeout=30) as r:
                        sun = json.load(r)["sun"]
                    break
                except OSError:
                    if server.poll() is not None or time.monotonic() > deadline:
                        print(server.stdout.read().decode(errors="replace") if server.poll() is not None else "")
                        print("Dcc.BlenderGreyBall: skyfarm-server did not answer")
                        return 1
                    time.sleep(0.1)
            out = os.path.join(work, name)
            os.makedirs(out)
            result_path = os.path.join(out, "result.json")
            cmd = [blender, "-b", "--factory-startup", "-noaudio",
                   "-P", os.path.join(args.source, "scripts/blender/skyfarm_world.py"),
                   "-P", os.path.join(args.source, "tests/dcc/grey_ball_scene.py"),
                   "--", "--server", base, "--lat", str(PLACE["lat"]), "--lon", str(PLACE["lon"]),
                   "--time", when, "--width", str(WIDTH), "--sun", sun_as, "--exr", os.path.join(out, "sky.exr")]
            start = time.monotonic()
            run = subprocess.run(cmd, capture_output=True, text=True, timeout=150,
                                 env={**env, "SKYFARM_DCC_OUT": out, "SKYFARM_DCC_RESULT": result_path})
            seconds = time.monotonic() - start
            if run.returncode != 0 or not os.path.exists(result_path):
                print(run.stdout[-4000:], run.stderr[-4000:])
                failures.append(f"{name}: blender exited {run.returncode} without a result")
                continue
            r = json.load(open(result_path))
            want_deg = 90.0 - sun["azimuth_deg"]  # north = +Y, east = +X; angles from +X counter-clockwise
            off = angle_difference(r["centroid_deg"], want_deg)
            e_h = r["horizontal_illuminance_lux"]
            want_top = r["albedo"] / math.pi * e_h
            got_top = LUMINOUS_EFFICACY * r["top"]
            exposed = r["top"] * 2.0 ** r["exposure"]
            print(f"{name}: sun azimuth {sun['azimuth_deg']:.1f} deg, zenith {sun['zenith_deg']:.1f} deg; "
                  f"ball brightest toward {r['centroid_deg']:.1f} deg from +X (want {want_deg:.1f}, off {off:.1f}); "
                  f"E_h {e_h:.0f} lux; 683 x top {got_top:.0f} vs albedo/pi E_h {want_top:.0f} "
                  f"(ratio {got_top / want_top:.4f}); exposure {r['exposure']:.3f} EV -> top {exposed:.3f} "
                  f"({r['view_transform']} display {r['top_display']:.3f}); blender {seconds:.1f} s")
            if off > ORIENTATION_TOLERANCE_DEG:
                failures.append(f"{name}: brightest side {r['centroid_deg']:.1f} deg, sun at {want_deg:.1f} deg")
            if abs(got_top / want_top - 1.0) > BRIGHTNESS_TOLERANCE:
                failures.append(f"{name}: 683 x top = {got_top:.0f}, albedo/pi E_h = {want_top:.0f}")
            if abs(exposed / r["albedo"] - 1.0) > BRIGHTNESS_TOLERANCE:
                failures.append(f"{name}: exposed top {exposed:.3f}, want {r['albedo']}")
            if r["sun_lamps"] != (1 if sun_as == "lamp" else 0):
                failures.append(f"{name}: {r['sun_lamps']} sun lamps with --sun {sun_as}")
            if abs(r["script_horizontal_illuminance_lux"] / e_h - 1.0) > 0.01:
                failures.append(f"{name}: the script's E_h {r['script_horizontal_illuminance_lux']:.0f} != {e_h:.0f}")
    finally:
        server.terminate()
        try:
            server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()
        shutil.rmtree(work, ignore_errors=True)
    for f in failures:
        print("Dcc.BlenderGreyBall: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
