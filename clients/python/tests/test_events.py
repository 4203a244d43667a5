"""The client's parsing and waiting against a scripted HTTP server: SSE
frames, resuming a dropped stream with Last-Event-ID, polling when the
stream is refused, problem documents.  No farm needed."""

import io
import json
import os
import sys
import threading
import unittest
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))

import skyfarm  # noqa: E402
from skyfarm.errors import problem_error  # noqa: E402
from skyfarm.sse import EventParser, iter_events  # noqa: E402


def status(state, fraction, spp=0, error=None):
    return {"id": "r1", "state": state, "progress": {"fraction": fraction, "samples_per_pixel": spp},
            "error": {"estimated_relative_rms": error}}


def frame(sequence, event, document):
    return ("id: %d\nevent: %s\ndata: %s\n\n" % (sequence, event, json.dumps(document))).encode()


class ScriptedFarm:
    """Answers /v1/renders/r1 and /v1/renders/r1/events from a script:
    ``streams`` is a list, one entry per connection to the events, each the
    bytes to send before closing (or the int 503 to refuse); ``statuses``
    the documents successive status polls answer (the last repeats); POST
    /v1/renders is refused ``refusals`` times (429, Retry-After 0), then
    accepted."""

    def __init__(self, streams=(), statuses=(), refusals=0):
        self.refusals = refusals  # POST /v1/renders answers 429 this many times first
        self.posts = 0
        self.streams = list(streams)
        self.statuses = list(statuses)
        self.last_event_ids = []  # the Last-Event-ID header of each stream request
        self.status_polls = 0
        farm = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def do_POST(self):
                self.rfile.read(int(self.headers.get("Content-Length", 0)))
                farm.posts += 1
                if farm.refusals:
                    farm.refusals -= 1
                    body = json.dumps({"type": "urn:skyfarm:problem:capacity-exceeded", "status": 429,
                                       "title": "The farm is at capacity", "detail": "64 active jobs"}).encode()
                    self.send_response(429)
                    self.send_header("Content-Type", "application/problem+json")
                    self.send_header("Retry-After", "0")
                else:
                    body = json.dumps({"id": "r1", "state": "queued", "created": True, "from_cache": False,
                                       "links": {"self": "/v1/renders/r1"}}).encode()
                    self.send_response(202)
                    self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def do_GET(self):
                if self.path == "/v1/renders/r1/events":
                    farm.last_event_ids.append(self.headers.get("Last-Event-ID"))
                    script = farm.streams.pop(0) if farm.streams else b""
                    if script == 503:
                        body = json.dumps({"type": "urn:skyfarm:problem:too-many-streams", "status": 503,
                                           "title": "Too many event streams", "detail": "retry"}).encode()
                        self.send_response(503)
                        self.send_header("Content-Type", "application/problem+json")
                        self.send_header("Retry-After", "5")
                        self.send_header("Content-Length", str(len(body)))
                        self.end_headers()
                        self.wfile.write(body)
                        return
                    # HTTP/1.0, no length: the body ends when the connection
                    # closes, which is how a dropped stream looks.
                    self.send_response(200)
                    self.send_header("Content-Type", "text/event-stream")
                    self.end_headers()
                    self.wfile.write(script)
                    self.wfile.flush()
                    self.close_connection = True
                elif self.path == "/v1/renders/r1":
                    index = min(farm.status_polls, len(farm.statuses) - 1)
                    farm.status_polls += 1
                    body = json.dumps(farm.statuses[index]).encode()
                    self.send_response(200)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(body)))
                    self.end_headers()
                    self.wfile.write(body)
                else:
                    self.send_error(404)

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.thread.start()
        self.url = "http://127.0.0.1:%d" % self.server.server_address[1]

    def close(self):
        self.server.shutdown()
        self.server.server_close()


class EventParserTest(unittest.TestCase):
    def test_frames_comments_and_line_endings(self):
        # HTML Living Standard 9.2.6: comments ignored, one space after the
        # colon removed, data lines joined by LF, CRLF / LF / CR endings.
        stream = io.BytesIO(b": keepalive\n\nid: 7\r\nevent: progress\r\ndata: {\"a\":\r\ndata:1}\r\n\r\n"
                            b"data: x\rid: 9\revent: done\r\r")
        events = list(iter_events(stream))
        self.assertEqual(events[0], ("7", "progress", '{"a":\n1}'))
        self.assertEqual(events[1], ("9", "done", "x"))
        self.assertEqual(len(events), 2)

    def test_id_is_kept_and_type_defaults_to_message(self):
        parser = EventParser(last_event_id="3")
        self.assertIsNone(parser.feed("data: a"))
        self.assertEqual(parser.feed(""), ("3", "message", "a"))
        # An event without data is not dispatched, but its id stays.
        parser.feed("id: 4")
        self.assertIsNone(parser.feed(""))
        self.assertEqual(parser.last_event_id, "4")


class WaitTest(unittest.TestCase):
    def test_dropped_stream_resumes_after_the_last_event(self):
        farm = ScriptedFarm(
            streams=[frame(1, "progress", status("running", 0.25, 4, 0.4)) +
                     frame(2, "progress", status("running", 0.5, 8, 0.2)),  # then the connection drops
                     frame(3, "done", status("done", 1.0, 16, 0.1))],
            statuses=[status("running", 0.5, 8, 0.2)])
        self.addCleanup(farm.close)
        seen = []
        final = skyfarm.Client(farm.url).get_render("r1").wait(progress=seen.append)
        self.assertEqual(final["state"], "done")
        self.assertEqual([s["progress"]["fraction"] for s in seen], [0.25, 0.5, 1.0])
        # The second connection asked for the events after id 2, none again.
        self.assertEqual(farm.last_event_ids, [None, "2"])

    def test_refused_stream_falls_back_to_polling(self):
        farm = ScriptedFarm(streams=[503],
                            statuses=[status("running", 0.1), status("running", 0.1), status("running", 0.6),
                                      status("done", 1.0)])
        self.addCleanup(farm.close)
        seen = []
        final = skyfarm.Client(farm.url).get_render("r1").wait(progress=seen.append, poll_interval=0.01)
        self.assertEqual(final["state"], "done")
        self.assertEqual(farm.status_polls, 4)
        # Unchanged documents are not reported twice.
        self.assertEqual([s["progress"]["fraction"] for s in seen], [0.1, 0.6, 1.0])

    def test_failed_render_raises(self):
        failed = dict(status("failed", 0.3), failure="worker crashed")
        farm = ScriptedFarm(streams=[frame(1, "failed", failed)], statuses=[failed])
        self.addCleanup(farm.close)
        with self.assertRaises(skyfarm.RenderFailed) as caught:
            skyfarm.Client(farm.url).get_render("r1").wait()
        self.assertEqual(caught.exception.state, "failed")
        self.assertIn("worker crashed", str(caught.exception))


class BusyTest(unittest.TestCase):
    def test_busy_wait_retries_a_refused_submission(self):
        farm = ScriptedFarm(refusals=2)
        self.addCleanup(farm.close)
        render = skyfarm.Client(farm.url, busy_wait_s=5).submit({"camera": {"projection": "fisheye"}})
        self.assertEqual(render.id, "r1")
        self.assertEqual(farm.posts, 3)

    def test_no_busy_wait_raises_at_once(self):
        farm = ScriptedFarm(refusals=1)
        self.addCleanup(farm.close)
        with self.assertRaises(skyfarm.TooManyRequests) as caught:
            skyfarm.Client(farm.url).submit({"camera": {"projection": "fisheye"}})
        self.assertEqual(caught.exception.retry_after, 0)
        self.assertEqual(farm.posts, 1)


class ProblemTest(unittest.TestCase):
    def test_validation_problem_names_each_field(self):
        body = json.dumps({
            "type": "urn:skyfarm:problem:validation-error", "title": "The request is invalid", "status": 400,
            "detail": "2 invalid fields",
            "errors": [{"field": "camera.fov_deg", "rule": "must be in (0, 180]", "value": "200",
                        "message": "camera.fov_deg: must be in (0, 180], got 200"},
                       {"field": "", "rule": "required", "value": "", "message": "(request): required"}]}).encode()
        error = problem_error(400, body, "application/problem+json")
        self.assertIsInstance(error, skyfarm.ValidationError)
        self.assertEqual(error.status, 400)
        self.assertEqual(error.errors, [("camera.fov_deg", "must be in (0, 180], got 200"), ("", "required")])
        self.assertEqual(str(error), "camera.fov_deg: must be in (0, 180], got 200; (request): required")

    def test_status_picks_the_class(self):
        self.assertIsInstance(problem_error(404, b'{"status":404,"title":"Not Found","detail":"no"}'),
                              skyfarm.NotFound)
        error = problem_error(503, b"<html>busy</html>", "text/html")
        self.assertIsInstance(error, skyfarm.ServerError)
        self.assertIn("busy", str(error))


if __name__ == "__main__":
    unittest.main()
