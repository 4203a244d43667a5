"""The ``skyfarm`` command end to end: ``python3 -m skyfarm`` from the
source tree, in a subprocess, against a real skyfarm-server."""

import json
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

import skyfarm  # noqa: E402
from farm_server import CLIENT_DIR, EXR_MAGIC, PNG_SIGNATURE, SOURCE_DIR, FarmServer, png_size, scratch  # noqa: E402

farm = None


def setUpModule():
    global farm
    farm = FarmServer(local_workers=2)


def tearDownModule():
    if farm is not None:
        farm.stop()


def skyfarm_cli(*args, env_server=True):
    """(exit status, stdout, stderr) of ``python3 -m skyfarm ARGS``; the
    server comes from SKYFARM_URL, as a user's shell would set it."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("SKYFARM_")}
    env["PYTHONPATH"] = CLIENT_DIR
    if env_server:
        env["SKYFARM_URL"] = farm.url
    done = subprocess.run([sys.executable, "-m", "skyfarm"] + list(args), env=env, capture_output=True,
                          timeout=120)
    return done.returncode, done.stdout.decode(), done.stderr.decode()


class CliTest(unittest.TestCase):
    def setUp(self):
        self.folder = scratch(self, "skyfarm-pyclient-cli-")

    def write_request(self, request, name="request.json"):
        path = os.path.join(self.folder, name)
        with open(path, "w") as f:
            json.dump(request, f)
        return path

    def test_render_writes_exr_and_png_and_shows_progress(self):
        request = self.write_request({"sun": {"zenith_deg": 40, "azimuth_deg": 180}, "seed": 201,
                                      "camera": {"projection": "equirectangular", "width": 16, "height": 8},
                                      "quality": {"samples_per_pixel": 8}})
        exr, png = os.path.join(self.folder, "sky.exr"), os.path.join(self.folder, "sky.png")
        code, out, err = skyfarm_cli("render", request, "-o", exr, "--png", png, "--json")
        self.assertEqual(code, 0, err)
        with open(exr, "rb") as f:
            self.assertEqual(f.read(4), EXR_MAGIC)
        with open(png, "rb") as f:
            data = f.read()
        self.assertEqual(data[:8], PNG_SIGNATURE)
        self.assertEqual(png_size(data), (16, 8))
        status = json.loads(out)
        self.assertEqual(status["state"], "done")
        # The progress line (not a terminal: one line per change) ends at
        # 100 % with the samples per pixel and the error estimate.
        last = [line for line in err.splitlines() if "[" in line][-1]
        self.assertIn("100.0 %", last)
        self.assertIn("8 spp", last)
        self.assertIn("error ", last)

        code, out, _ = skyfarm_cli("status", status["id"])
        self.assertEqual(code, 0)
        self.assertEqual(json.loads(out)["id"], status["id"])

    def test_submit_wait_download(self):
        request = self.write_request({"sun": {"zenith_deg": 35, "azimuth_deg": 90}, "method": "lut",
                                      "camera": {"projection": "fisheye", "width": 8, "height": 8}})
        code, out, err = skyfarm_cli("submit", request)
        self.assertEqual(code, 0, err)
        answer = json.loads(out)
        self.assertEqual(answer["links"]["self"], "/v1/renders/" + answer["id"])
        code, out, err = skyfarm_cli("wait", answer["id"], "--json", "--quiet")
        self.assertEqual(code, 0, err)
        self.assertEqual(json.loads(out)["state"], "done")
        self.assertEqual(err, "")
        png = os.path.join(self.folder, "fisheye.png")
        code, _, err = skyfarm_cli("download", answer["id"], "--png", png)
        self.assertEqual(code, 0, err)
        with open(png, "rb") as f:
            self.assertEqual(png_size(f.read()), (8, 8))

    def test_invalid_request_exits_naming_the_field(self):
        request = self.write_request({"sun": {"zenith_deg": 30, "azimuth_deg": 180},
                                      "camera": {"projection": "perspective", "fov_deg": 200}})
        code, out, err = skyfarm_cli("render", request, "-o", os.path.join(self.folder, "x.exr"))
        self.assertEqual(code, 1)
        self.assertEqual(err.strip(), "skyfarm: error: camera.fov_deg: must be a number in (0, 179] for a "
                                      "perspective camera, got 200")
        self.assertEqual(out, "")

    def test_cancel(self):
        request = self.write_request({"sun": {"zenith_deg": 40, "azimuth_deg": 180}, "seed": 202,
                                      "camera": {"projection": "equirectangular", "width": 64, "height": 32},
                                      "quality": {"samples_per_pixel": 100000}})
        # Submitted with the library, then cancelled by the command.
        render = skyfarm.Client(farm.url).submit(request)
        code, out, err = skyfarm_cli("cancel", render.id)
        self.assertEqual(code, 0, err)
        self.assertEqual(json.loads(out)["id"], render.id)
        self.assertEqual(render.wait(timeout=30, raise_on_failure=False)["state"], "cancelled")

    def test_sky_prints_json(self):
        code, out, err = skyfarm_cli("sky", "--lat", "48.85", "--lon", "2.35", "--time", "2021-06-21T13:50:00+02:00",
                                     "--view-zenith", "30", "--view-azimuth", "180")
        self.assertEqual(code, 0, err)
        answer = json.loads(out)
        self.assertAlmostEqual(answer["sun"]["zenith_deg"], 25.4, delta=0.3)  # see test_farm.SkyTest
        self.assertEqual(answer["view"], {"zenith_deg": 30.0, "azimuth_deg": 180.0})

    def test_sky_bad_parameter_exits_naming_it(self):
        code, _, err = skyfarm_cli("sky", "--lat", "123", "--time", "2021-06-21T13:50:00+02:00",
                                   "--view-zenith", "30", "--view-azimuth", "180")
        self.assertEqual(code, 1)
        self.assertIn("skyfarm: error: lat: ", err)

    def test_envmap(self):
        path = os.path.join(self.folder, "env.exr")
        # The server given by flag, after the command, this time.
        code, _, err = skyfarm_cli("envmap", "--lat", "48.85", "--time", "2021-06-21T13:50:00+02:00", "--width", "16",
                                   "-o", path, "--server", farm.url, env_server=False)
        self.assertEqual(code, 0, err)
        with open(path, "rb") as f:
            self.assertEqual(f.read(4), EXR_MAGIC)

    def test_timelapse(self):
        request = self.write_request({
            "location": {"latitude_deg": 42.44, "longitude_deg": -76.48},
            "start": "2013-05-27T19:00:00-04:00", "end": "2013-05-27T19:10:00-04:00", "frames": 2,
            "camera": {"projection": "equirectangular", "width": 16, "height": 8}, "method": "lut",
            "seed": 203})
        out_dir = os.path.join(self.folder, "timelapse")
        code, _, err = skyfarm_cli("timelapse", request, "-o", out_dir, "--no-exr")
        self.assertEqual(code, 0, err)
        files = sorted(os.listdir(out_dir))
        self.assertIn("contact_sheet.png", files)
        self.assertIn("frame_0001.png", files)
        self.assertNotIn("frame_0000.exr", files)

    def test_probe_prints_json(self):
        request = self.write_request({"sun": {"zenith_deg": 30, "azimuth_deg": 180}, "method": "lut",
                                      "directions": [{"zenith_deg": 10, "azimuth_deg": 0}], "wavelengths_nm": [500]})
        code, out, err = skyfarm_cli("probe", request)
        self.assertEqual(code, 0, err)
        answer = json.loads(out)
        self.assertEqual(answer["wavelengths_nm"], [500])
        self.assertGreater(answer["radiance"][0][0], 0)

    def test_assets_upload_get_download(self):
        mesh = os.path.join(SOURCE_DIR, "api", "examples", "assets", "pavilion.obj")
        code, out, err = skyfarm_cli("assets", "upload", mesh)
        self.assertEqual(code, 0, err)
        asset = json.loads(out)
        code, out, err = skyfarm_cli("assets", "get", asset["id"])
        self.assertEqual(code, 0, err)
        self.assertEqual(json.loads(out)["id"], asset["id"])
        path = os.path.join(self.folder, "mesh.bin")
        code, _, err = skyfarm_cli("assets", "download", asset["id"], "-o", path)
        self.assertEqual(code, 0, err)
        self.assertEqual(os.path.getsize(path), asset["bytes"])
        code, _, err = skyfarm_cli("assets", "get", "sha256:nothex")
        self.assertEqual(code, 1)
        self.assertIn("skyfarm: error: id: ", err)

    def test_workers_and_no_server(self):
        code, out, err = skyfarm_cli("workers")
        self.assertEqual(code, 0, err)
        self.assertIsInstance(json.loads(out), list)
        code, _, err = skyfarm_cli("workers", "--server", "http://127.0.0.1:9", env_server=False)
        self.assertEqual(code, 1)
        self.assertIn("cannot reach http://127.0.0.1:9", err)


if __name__ == "__main__":
    unittest.main()
