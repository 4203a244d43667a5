"""The client against a real skyfarm-server with two local workers: submit
and wait (progress reported and increasing), download, cancel, problems
naming the field, the sky look-ups, probes, timelapses, assets, workers,
the bearer token.  Tiny requests: the whole module runs in seconds."""

import datetime
import hashlib
import os
import sys
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

import skyfarm  # noqa: E402
from farm_server import EXR_MAGIC, PNG_SIGNATURE, SOURCE_DIR, FarmServer, png_size, scratch  # noqa: E402

farm = None


def setUpModule():
    global farm
    farm = FarmServer(local_workers=2)


def tearDownModule():
    if farm is not None:
        farm.stop()


# A path-traced 16 x 8 panorama: a few passes on two workers, each merged
# pass an event; the seed makes it a new render for every test that wants one.
def path_request(seed, spp=16, width=16, height=8):
    return {"sun": {"zenith_deg": 40, "azimuth_deg": 180},
            "camera": {"projection": "equirectangular", "width": width, "height": height},
            "quality": {"samples_per_pixel": spp}, "seed": seed}


LUT_REQUEST = {"sun": {"zenith_deg": 30, "azimuth_deg": 180},
               "camera": {"projection": "equirectangular", "width": 16, "height": 8}, "method": "lut"}


class RenderTest(unittest.TestCase):
    def setUp(self):
        self.client = skyfarm.Client(farm.url)
        self.folder = scratch(self, "skyfarm-pyclient-out-")

    def test_submit_wait_reports_increasing_progress(self):
        # 32 x 16 at 512 spp: 32 passes of 16 samples, about a second on
        # two workers, so several passes are merged between events.
        render = self.client.submit(path_request(seed=101, spp=512, width=32, height=16))
        self.assertTrue(render.created)
        seen = []
        final = render.wait(progress=seen.append, timeout=60)
        self.assertEqual(final["state"], "done")
        self.assertIs(seen[-1], final)
        fractions = [s["progress"]["fraction"] for s in seen]
        self.assertEqual(fractions, sorted(fractions), "progress never goes back")
        self.assertEqual(fractions[-1], 1.0)
        self.assertTrue(any(0 < f < 1 for f in fractions), fractions)
        self.assertEqual(final["progress"]["samples_per_pixel"], 512)
        # The error estimate of the first report and the last: Monte Carlo
        # error falls as 1/sqrt(samples), so their ratio is
        # sqrt(spp_last / spp_first) (within 10 %; measured: 2 % for this seed).
        estimated = [(s["progress"]["samples_per_pixel"], s["error"]["estimated_relative_rms"])
                     for s in seen if s["error"]["estimated_relative_rms"] is not None]
        (spp_first, error_first), (spp_last, error_last) = estimated[0], estimated[-1]
        self.assertLess(spp_first, spp_last)
        expected = (spp_last / spp_first) ** 0.5
        self.assertAlmostEqual(error_first / error_last / expected, 1.0, delta=0.1)

    def test_download_exr_and_png(self):
        render = self.client.submit(LUT_REQUEST)
        render.wait(timeout=60)
        exr = render.download(os.path.join(self.folder, "sky.exr"))
        png = render.download(os.path.join(self.folder, "sky.png"))
        with open(exr, "rb") as f:
            self.assertEqual(f.read(4), EXR_MAGIC)
        with open(png, "rb") as f:
            data = f.read()
        self.assertEqual(data[:8], PNG_SIGNATURE)
        self.assertEqual(png_size(data), (16, 8))
        self.assertEqual(render.image("png"), data)

    def test_same_request_with_a_key_answers_the_same_render(self):
        first = self.client.submit(path_request(seed=102, spp=4), idempotency_key="pyclient-key-102")
        again = self.client.submit(path_request(seed=102, spp=4), idempotency_key="pyclient-key-102")
        self.assertEqual(first.id, again.id)
        self.assertTrue(first.created)
        self.assertFalse(again.created)
        with self.assertRaises(skyfarm.Unprocessable) as caught:
            self.client.submit(path_request(seed=103, spp=4), idempotency_key="pyclient-key-102")
        self.assertEqual(caught.exception.status, 422)
        first.wait(timeout=60)

    def test_cancel(self):
        render = self.client.submit(path_request(seed=104, spp=100000, width=64, height=32))
        answer = render.cancel()
        self.assertEqual(answer["id"], render.id)
        with self.assertRaises(skyfarm.RenderFailed) as caught:
            render.wait(timeout=30)
        self.assertEqual(caught.exception.state, "cancelled")
        self.assertEqual(render.status()["state"], "cancelled")
        with self.assertRaises(skyfarm.Conflict):
            render.download(os.path.join(self.folder, "none.exr"))
        self.assertFalse(os.path.exists(os.path.join(self.folder, "none.exr")))
        render.cancel(purge=True)
        with self.assertRaises(skyfarm.NotFound):
            render.status()

    def test_invalid_request_names_the_field(self):
        request = {"sun": {"zenith_deg": 30, "azimuth_deg": 180},
                   "camera": {"projection": "perspective", "width": 16, "height": 8, "fov_deg": 200}}
        with self.assertRaises(skyfarm.ValidationError) as caught:
            self.client.submit(request)
        error = caught.exception
        self.assertEqual(error.status, 400)
        self.assertEqual(error.fields, ["camera.fov_deg"])
        self.assertEqual(str(error), "camera.fov_deg: must be a number in (0, 179] for a perspective camera, got 200")

    def test_renders_lists_the_submitted(self):
        render = self.client.submit(LUT_REQUEST)
        page = self.client.renders(limit=100)
        self.assertIn(render.id, [r["id"] for r in page])
        self.assertGreaterEqual(page.total, 1)
        with self.assertRaises(skyfarm.ValidationError) as caught:
            self.client.renders(limit=0)
        self.assertEqual(caught.exception.fields, ["limit"])


class SkyTest(unittest.TestCase):
    def setUp(self):
        self.client = skyfarm.Client(farm.url)

    def test_sky_places_the_sun_from_the_time(self):
        # Paris at the June solstice near solar noon (13:50 CEST): the sun's
        # zenith angle is the latitude less the declination, 48.85 - 23.44 =
        # 25.4 degrees (NOAA solar calculator: 25.4).  The "+02:00" must
        # reach the server as a plus.
        answer = self.client.sky(lat=48.85, lon=2.35, time="2021-06-21T13:50:00+02:00",
                                 view_zenith=30, view_azimuth=180)
        self.assertEqual(answer["method"], "lut")
        self.assertAlmostEqual(answer["sun"]["zenith_deg"], 25.4, delta=0.3)
        self.assertGreater(answer["luminance_cd_m2"], 0)
        self.assertEqual(answer["luminance_cd_m2"], answer["xyz"]["Y"])
        # An aware datetime is the same instant.
        cest = datetime.timezone(datetime.timedelta(hours=2))
        again = self.client.sky(lat=48.85, lon=2.35, time=datetime.datetime(2021, 6, 21, 13, 50, tzinfo=cest),
                                view_zenith=30, view_azimuth=180)
        self.assertEqual(again, answer)

    def test_sky_bad_parameter_names_it(self):
        with self.assertRaises(skyfarm.ValidationError) as caught:
            self.client.sky(lat=48.85, time="2021-06-21T13:50:00+02:00", view_zenith=200, view_azimuth=0)
        self.assertEqual(caught.exception.fields, ["view_zenith"])

    def test_envmap(self):
        data = self.client.envmap(sun_zenith=60, sun_azimuth=120, width=16)
        self.assertEqual(data[:4], EXR_MAGIC)
        path = os.path.join(scratch(self, "skyfarm-pyclient-env-"), "env.exr")
        self.assertEqual(self.client.envmap(path, sun_zenith=60, sun_azimuth=120, width=16), path)
        with open(path, "rb") as f:
            self.assertEqual(f.read(), data)  # the server's cached bytes

    def test_probe(self):
        request = {"sun": {"zenith_deg": 30, "azimuth_deg": 180},
                   "directions": [{"zenith_deg": 0, "azimuth_deg": 0}, {"zenith_deg": 60, "azimuth_deg": 90}],
                   "wavelengths_nm": [450, 550], "method": "lut"}
        answer = self.client.probe(request)
        self.assertEqual(len(answer["radiance"]), 2)
        self.assertEqual(len(answer["radiance"][0]), 2)
        self.assertIsNone(answer["standard_error"])
        # Rayleigh: the zenith of a clear sky is bluer than green.
        self.assertGreater(answer["radiance"][0][0], answer["radiance"][0][1])


class FarmTest(unittest.TestCase):
    def setUp(self):
        self.client = skyfarm.Client(farm.url)

    def test_workers(self):
        workers = []
        for _ in range(100):  # the local workers connect within a second or two
            workers = self.client.workers()
            if len(workers) == 2:
                break
            time.sleep(0.1)
        self.assertEqual(len(workers), 2)
        self.assertTrue(all("id" in w for w in workers))
        self.assertTrue(self.client.health())

    def test_timelapse(self):
        edt = datetime.timezone(datetime.timedelta(hours=-4))  # datetimes go as ISO 8601
        request = dict(LUT_REQUEST, start=datetime.datetime(2013, 5, 27, 19, 0, tzinfo=edt),
                       end=datetime.datetime(2013, 5, 27, 19, 10, tzinfo=edt),
                       frames=2, location={"latitude_deg": 42.44, "longitude_deg": -76.48})
        del request["sun"]
        timelapse = self.client.timelapse(request)
        final = timelapse.wait(timeout=60, poll_interval=0.2)
        self.assertEqual(final["state"], "done")
        self.assertEqual(final["progress"]["frames_done"], 2)
        self.assertEqual([f["time"] for f in final["frames"]],
                         ["2013-05-27T19:00:00-04:00", "2013-05-27T19:10:00-04:00"])
        folder = scratch(self, "skyfarm-pyclient-tl-")
        written = timelapse.download(folder)
        names = sorted(os.path.basename(p) for p in written)
        expected = ["contact_sheet.png", "frame_0000.exr", "frame_0000.png", "frame_0001.exr", "frame_0001.png"]
        if final["video"]["available"]:
            expected.append("video.mp4")
        self.assertEqual(names, sorted(expected))
        with open(os.path.join(folder, "contact_sheet.png"), "rb") as f:
            # api/openapi.yaml: 192 px cells, 8 px padding, 11 px of caption:
            # 2 frames of 16 x 8 are 2 x 192 + 3 x 8 = 408 by 96 + 11 + 2 x 8 = 123.
            self.assertEqual(png_size(f.read()), (408, 123))
        with open(os.path.join(folder, "frame_0001.exr"), "rb") as f:
            self.assertEqual(f.read(4), EXR_MAGIC)
        self.assertEqual(timelapse.frame_render(0).status()["state"], "done")

    def test_assets(self):
        mesh = os.path.join(SOURCE_DIR, "api", "examples", "assets", "pavilion.obj")
        asset = self.client.assets.upload(mesh, format="obj")
        self.assertTrue(asset["id"].startswith("sha256:"))
        self.assertEqual(self.client.assets.get(asset["id"])["triangles"], asset["triangles"])
        path = os.path.join(scratch(self, "skyfarm-pyclient-asset-"), "pavilion.skymesh")
        self.client.assets.download(asset["id"], path)
        with open(path, "rb") as f:
            data = f.read()
        self.assertEqual(data[:8], b"SKYMESH1")
        self.assertEqual("sha256:" + hashlib.sha256(data).hexdigest(), asset["id"])  # the id is its hash


class CapacityTest(unittest.TestCase):
    def test_full_farm_answers_429_with_retry_after(self):
        # One active job allowed and no workers: the first render stays
        # queued, the second is refused for now.
        full = FarmServer(local_workers=0, extra=["--max-active-jobs", "1"])
        self.addCleanup(full.stop)
        client = skyfarm.Client(full.url)
        client.submit(LUT_REQUEST)
        with self.assertRaises(skyfarm.TooManyRequests) as caught:
            client.submit(path_request(seed=105))
        self.assertEqual(caught.exception.status, 429)
        self.assertEqual(caught.exception.retry_after, 10)  # server/http/http_problem.cpp
        # Waiting less than the Retry-After does not try again.
        started = time.monotonic()
        with self.assertRaises(skyfarm.TooManyRequests):
            skyfarm.Client(full.url, busy_wait_s=5).submit(path_request(seed=105))
        self.assertLess(time.monotonic() - started, 5)


class TokenTest(unittest.TestCase):
    def test_bearer_token(self):
        guarded = FarmServer(local_workers=0, token="s3cret-token")
        self.addCleanup(guarded.stop)
        with self.assertRaises(skyfarm.Unauthorized) as caught:
            skyfarm.Client(guarded.url, token="").workers()
        self.assertEqual(caught.exception.status, 401)
        with self.assertRaises(skyfarm.Unauthorized):
            skyfarm.Client(guarded.url, token="wrong").workers()
        client = skyfarm.Client(guarded.url, token="s3cret-token")
        self.assertEqual(client.workers(), [])
        self.assertTrue(skyfarm.Client(guarded.url, token="").health())


if __name__ == "__main__":
    unittest.main()
