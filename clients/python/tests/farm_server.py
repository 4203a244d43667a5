"""Test support: a real skyfarm-server with local workers on a free port.

The binaries come from the environment (CTest sets them from the build):
SKYFARM_TEST_SERVER_BINARY and SKYFARM_TEST_WORKER_BINARY; without them,
build/server/skyfarm-server and build/worker/skyfarm-worker of the source
tree.  The server runs in a temporary data directory with every other
SKYFARM_* variable removed from its environment (it reads its flags from
them: SKYFARM_TOKEN would change what is tested).
"""

import os
import re
import shutil
import subprocess
import tempfile
import threading

SOURCE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
CLIENT_DIR = os.path.join(SOURCE_DIR, "clients", "python")


def binary(variable, default):
    path = os.environ.get(variable) or os.path.join(SOURCE_DIR, default)
    if not os.access(path, os.X_OK):
        raise RuntimeError("%s: no program at %s (build it, or set the variable)" % (variable, path))
    return path


class FarmServer:
    """``FarmServer(local_workers=2, token=None, extra=())``: started at
    once (``extra``: more flags); ``url``, ``log()``, ``stop()``."""

    _READY = re.compile(r"HTTP on http://127\.0\.0\.1:(\d+), broker on (\S+),")

    def __init__(self, local_workers=2, token=None, extra=(), start_timeout_s=20.0):
        self.folder = tempfile.mkdtemp(prefix="skyfarm-pyclient-")
        args = [binary("SKYFARM_TEST_SERVER_BINARY", "build/server/skyfarm-server"),
                "--listen", "127.0.0.1:0", "--broker", "tcp://127.0.0.1:*",
                "--local-workers", str(local_workers), "--data-dir", os.path.join(self.folder, "data"),
                "--worker-binary", binary("SKYFARM_TEST_WORKER_BINARY", "build/worker/skyfarm-worker")]
        if token:
            args += ["--token", token]
        args += list(extra)
        env = {k: v for k, v in os.environ.items() if not k.startswith("SKYFARM_")}
        self._lines = []
        self._ready = threading.Event()
        self.port = None
        self.process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env)
        # One thread drains the output (a full pipe would block the server)
        # and finds the line naming the port.
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        if not self._ready.wait(start_timeout_s) or self.port is None:
            self.stop()
            raise RuntimeError("skyfarm-server did not start:\n" + self.log())
        self.url = "http://127.0.0.1:%d" % self.port

    def _read(self):
        for raw in iter(self.process.stdout.readline, b""):
            line = raw.decode("utf-8", "replace")
            self._lines.append(line)
            match = self._READY.search(line)
            if match and self.port is None:
                self.port = int(match.group(1))
                self._ready.set()
        self._ready.set()  # exited

    def log(self):
        return "".join(self._lines)

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(15)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self._reader.join(5)
        self.process.stdout.close()
        shutil.rmtree(self.folder, ignore_errors=True)


EXR_MAGIC = b"\x76\x2f\x31\x01"   # OpenEXR file layout, "magic number": 20000630 little-endian
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"  # PNG specification (ISO/IEC 15948), 5.2


def scratch(test, prefix):
    """A temporary folder removed after the test."""
    folder = tempfile.mkdtemp(prefix=prefix)
    test.addCleanup(shutil.rmtree, folder, True)
    return folder


def png_size(data):
    """(width, height) from a PNG's IHDR chunk, which must come first."""
    if data[:8] != PNG_SIGNATURE or data[12:16] != b"IHDR":
        raise ValueError("not a PNG")
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
