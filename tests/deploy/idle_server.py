"""A skyfarm-server for the deployment tests to ask: on free loopback ports,
no workers, a temporary data directory, stopped with SIGTERM.

    with idle_server(binary) as url:      # once /healthz answers
        urllib.request.urlopen(url + "/metrics")
"""
import contextlib
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def idle_server(server_binary, timeout_s=20):
    """Yields the server's base URL; exits the test with the server's output
    when it does not answer /healthz within timeout_s."""
    http, broker = free_port(), free_port()
    env = {k: v for k, v in os.environ.items() if not k.startswith("SKYFARM_")}
    with tempfile.TemporaryDirectory() as data:
        proc = subprocess.Popen([server_binary, "--listen", f"127.0.0.1:{http}", "--broker",
                                 f"tcp://127.0.0.1:{broker}", "--local-workers", "0", "--data-dir", data],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env, cwd=data)
        url = f"http://127.0.0.1:{http}"
        try:
            deadline = time.monotonic() + timeout_s
            while True:
                try:
                    with urllib.request.urlopen(url + "/healthz", timeout=2):
                        break
                except OSError:
                    if proc.poll() is not None or time.monotonic() > deadline:
                        sys.exit("skyfarm-server did not answer /healthz: " + proc.stdout.read().decode())
                    time.sleep(0.1)
            yield url
        finally:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
