#!/usr/bin/env python3
"""Run by install_test.sh, possibly with the source tree hidden: the installed
programs render a tiny sky, alone and as a farm.

usage: installed_run.py PREFIX WORKDIR [HIDDEN_DIR...]
  HIDDEN_DIR  directories that must look empty (the source and build trees)
"""
import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request

REQUEST = {
    "sun": {"zenith_deg": 40, "azimuth_deg": 180},
    "camera": {"projection": "fisheye", "width": 16, "height": 16},
    "quality": {"samples_per_pixel": 1},
}
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
EXR_MAGIC = b"\x76\x2f\x31\x01"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def fail(text):
    sys.exit(f"Deploy.Install: {text}")


def main():
    prefix, work = sys.argv[1], sys.argv[2]
    for hidden in sys.argv[3:]:
        if os.path.isdir(hidden) and os.listdir(hidden):
            fail(f"{hidden} is not hidden")
    os.chdir(work)
    env = {k: v for k, v in os.environ.items() if not k.startswith("SKYFARM_")}
    with open("request.json", "w") as f:
        json.dump(REQUEST, f)

    # Alone.
    out = subprocess.run([f"{prefix}/bin/skyfarm-worker", "render", "request.json", "-o", "sky.exr",
                          "--png", "sky.png", "--threads", "1"], capture_output=True, text=True, env=env, timeout=60)
    if out.returncode != 0:
        fail(f"skyfarm-worker render exited {out.returncode}: {out.stderr}")
    if open("sky.exr", "rb").read(4) != EXR_MAGIC or open("sky.png", "rb").read(8) != PNG_MAGIC:
        fail("skyfarm-worker render wrote no EXR and PNG")

    # As a farm: the server finds the installed worker next to itself.
    http, broker = free_port(), free_port()
    server = subprocess.Popen([f"{prefix}/bin/skyfarm-server", "--listen", f"127.0.0.1:{http}", "--broker",
                               f"tcp://127.0.0.1:{broker}", "--local-workers", "1", "--data-dir", "data"],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env)
    base = f"http://127.0.0.1:{http}"
    try:
        deadline = time.monotonic() + 45
        while True:
            try:
                body = json.dumps(REQUEST).encode()
                req = urllib.request.Request(f"{base}/v1/renders", data=body,
                                             headers={"Content-Type": "application/json"})
                with urllib.request.urlopen(req, timeout=5) as r:
                    location = r.headers["Location"]
                break
            except OSError:
                if server.poll() is not None or time.monotonic() > deadline:
                    fail("skyfarm-server did not take the render: " + server.stdout.read().decode())
                time.sleep(0.1)
        state = None
        while time.monotonic() < deadline:
            with urllib.request.urlopen(base + location, timeout=5) as r:
                state = json.load(r).get("state")
            if state in ("done", "failed", "cancelled"):
                break
            time.sleep(0.2)
        if state != "done":
            fail(f"the farm render ended '{state}' (its installed local worker did not render it)")
        with urllib.request.urlopen(f"{base}{location}/image.exr", timeout=10) as r:
            if r.read(4) != EXR_MAGIC:
                fail("the farm render's image.exr is not an EXR")
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
    print("Deploy.Install: the installed skyfarm-worker and skyfarm-server rendered from", prefix)


if __name__ == "__main__":
    main()
