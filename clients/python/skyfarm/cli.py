"""The ``skyfarm`` command: the client library from a shell.

    skyfarm [--server URL] [--token TOKEN] COMMAND ...

  --server URL   the farm (default $SKYFARM_URL, else http://127.0.0.1:8080)
  --token TOKEN  bearer token of a server run with --token (default $SKYFARM_TOKEN)
  --timeout S    seconds one HTTP exchange may take (default 60)
  --busy-wait S  retry for S seconds while the farm is at capacity (429)

Commands: render (= submit, wait, download), submit, wait, download, status,
cancel, renders, sky, envmap, probe, timelapse, timelapses, workers, assets
(``skyfarm COMMAND --help``).  JSON answers are
printed on stdout; progress and messages go to stderr.  Exit status: 0 done,
1 an error answer of the server (one line per invalid field, naming it) or
no server, 2 bad usage, 3 a render or timelapse that failed or was
cancelled, 130 interrupted (the render goes on on the server).
"""

import argparse
import json
import sys

from . import __version__
from .client import Client
from .errors import RenderFailed, SkyfarmError
from .progress import ProgressBar

EXIT_ERROR = 1
EXIT_USAGE = 2
EXIT_FAILED = 3
EXIT_INTERRUPTED = 130


def _print_json(document):
    json.dump(document, sys.stdout, indent=2, sort_keys=False)
    sys.stdout.write("\n")


def _note(text):
    sys.stderr.write(text + "\n")
    sys.stderr.flush()


def _query_pairs(pairs):
    """``-q name=value`` options as a dict (a name given twice keeps both)."""
    query = {}
    for pair in pairs or []:
        name, equals, value = pair.partition("=")
        if not equals or not name:
            raise SystemExit("skyfarm: error: -q takes name=value, not %r" % pair)
        query.setdefault(name, []).append(value)
    return {k: v[0] if len(v) == 1 else v for k, v in query.items()}


def _progress(args, label=None):
    return None if args.quiet else ProgressBar(sys.stderr, label=label)


# --- commands ----------------------------------------------------------------

def _wait(render, args):
    bar = _progress(args, label=render.id)
    try:
        return render.wait(progress=bar, timeout=args.wait_timeout)
    finally:
        if bar is not None:
            bar.close()


def _download(render, args):
    if args.output:
        _note("wrote " + render.download(args.output))
    if args.png:
        _note("wrote " + render.download(args.png, "png"))


def cmd_render(client, args):
    if not args.output and not args.png:
        raise SystemExit("skyfarm render: error: give -o FILE.exr and/or --png FILE.png")
    render = client.submit(args.request, idempotency_key=args.idempotency_key)
    how = ""
    if render.from_cache:
        how = " (from the result cache)"
    elif render.created is False:
        how = " (submitted before)"
    _note("render %s%s: %s%s" % (render.id, how, client.url, render.path))
    status = _wait(render, args)
    _download(render, args)
    if args.json:
        _print_json(status)
    return 0


def cmd_submit(client, args):
    _print_json(client.submit(args.request, idempotency_key=args.idempotency_key).answer)
    return 0


def cmd_wait(client, args):
    status = _wait(client.get_render(args.id), args)
    if args.json:
        _print_json(status)
    return 0


def cmd_download(client, args):
    if not args.output and not args.png:
        raise SystemExit("skyfarm download: error: give -o FILE.exr and/or --png FILE.png")
    _download(client.get_render(args.id), args)
    return 0


def cmd_status(client, args):
    handle = client.get_timelapse(args.id) if args.timelapse else client.get_render(args.id)
    _print_json(handle.status())
    return 0


def cmd_cancel(client, args):
    if args.timelapse:
        _print_json(client.get_timelapse(args.id).cancel())
    elif args.purge:
        client.get_render(args.id).cancel(purge=True)
        _note("purged render " + args.id)
    else:
        _print_json(client.get_render(args.id).cancel())
    return 0


def cmd_renders(client, args):
    page = client.renders(offset=args.offset, limit=args.limit)
    _print_json({"renders": list(page), "offset": page.offset, "limit": page.limit, "total": page.total})
    return 0


def cmd_timelapses(client, args):
    page = client.timelapses(offset=args.offset, limit=args.limit)
    _print_json({"timelapses": list(page), "offset": page.offset, "limit": page.limit, "total": page.total})
    return 0


# The /v1/sky and envmap query parameters with an option of their own;
# any other goes by -q name=value.
_SKY_OPTIONS = [("lat", float, "latitude, degrees north"), ("lon", float, "longitude, degrees east"),
                ("altitude", float, "observer altitude, m"),
                ("time", str, "ISO 8601 with a UTC offset, e.g. 2021-06-21T13:50:00+02:00"),
                ("sun-zenith", float, "sun zenith angle, degrees (with --sun-azimuth, instead of --time)"),
                ("sun-azimuth", float, "sun azimuth, degrees clockwise from north"),
                ("preset", str, "earth or earth_clear"), ("aod", float, "aerosol optical depth at 550 nm")]


def _sky_query(args):
    query = {name.replace("-", "_"): getattr(args, name.replace("-", "_")) for name, _, _ in _SKY_OPTIONS}
    query.update(_query_pairs(args.query))
    return query


def cmd_sky(client, args):
    query = _sky_query(args)
    query.update(view_zenith=args.view_zenith, view_azimuth=args.view_azimuth)
    _print_json(client.sky(**query))
    return 0


def cmd_envmap(client, args):
    query = _sky_query(args)
    query.update(width=args.width, sun=args.sun)
    _note("wrote " + client.envmap(args.output, **query))
    return 0


def cmd_probe(client, args):
    _print_json(client.probe(args.request))
    return 0


def cmd_timelapse(client, args):
    timelapse = client.timelapse(args.request, idempotency_key=args.idempotency_key)
    frames = (timelapse.answer.get("progress") or {}).get("frames_total", "?")
    _note("timelapse %s (%s frames): %s%s" % (timelapse.id, frames, client.url, timelapse.path))
    bar = _progress(args, label=timelapse.id)
    try:
        status = timelapse.wait(progress=bar, timeout=args.wait_timeout)
    finally:
        if bar is not None:
            bar.close()
    written = timelapse.download(args.output, exr=not args.no_exr, png=not args.no_png)
    _note("wrote %d files into %s" % (len(written), args.output))
    video = status.get("video") or {}
    if not video.get("available"):
        _note("no video: %s" % (video.get("reason") or "not made"))
    if args.json:
        _print_json(status)
    return 0


def cmd_workers(client, args):
    _print_json(client.workers())
    return 0


def cmd_assets(client, args):
    if args.assets_command == "upload":
        _print_json(client.assets.upload(args.file, format=args.format, grid=args.grid))
    elif args.assets_command == "get":
        _print_json(client.assets.get(args.id))
    else:
        _note("wrote " + client.assets.download(args.id, args.output))
    return 0


# --- the parser ----------------------------------------------------------------

def _connection_options(parser, suppress):
    """--server, --token, --timeout, --busy-wait: before the command, or after it
    (``suppress``: a subcommand's copy must not reset the main one's value)."""
    default = (lambda value: argparse.SUPPRESS) if suppress else (lambda value: value)
    parser.add_argument("--server", metavar="URL", default=default(None),
                        help="the farm's URL (default $SKYFARM_URL, else http://127.0.0.1:8080)")
    parser.add_argument("--token", default=default(None),
                        help="bearer token of a server run with --token (default $SKYFARM_TOKEN)")
    parser.add_argument("--timeout", type=float, metavar="S", default=default(60.0),
                        help="seconds one HTTP exchange may take (default 60)")
    parser.add_argument("--busy-wait", type=float, metavar="S", default=default(0.0),
                        help="keep retrying for S seconds while the farm answers 429 (at capacity) or 503 "
                             "with Retry-After (default 0: fail at once)")


def build_parser():
    parser = argparse.ArgumentParser(
        prog="skyfarm", description="Drive a skyfarm render farm: renders, timelapses, sky look-ups, assets.",
        epilog="Exit status: 0 done, 1 an error answer of the server (each invalid field named) or no server, "
               "2 bad usage, 3 a render or timelapse failed or was cancelled, 130 interrupted.")
    parser.add_argument("--version", action="version", version="skyfarm client " + __version__)
    _connection_options(parser, suppress=False)
    common = argparse.ArgumentParser(add_help=False)
    _connection_options(common, suppress=True)
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    commands.required = True

    def command(name, handler, help_text):
        p = commands.add_parser(name, parents=[common], help=help_text, description=help_text)
        p.set_defaults(handler=handler)
        return p

    def waits(p, submits=True):
        p.add_argument("--quiet", action="store_true", help="no progress bar")
        p.add_argument("--json", action="store_true", help="print the final status document on stdout")
        if submits:
            p.add_argument("--idempotency-key", metavar="KEY", help="makes a retried submission answer the same job")
        p.add_argument("--wait-timeout", type=float, metavar="S", help="give up waiting after S seconds")

    p = command("render", cmd_render, "submit a render request, show its progress, download the image")
    p.add_argument("request", help="the request's JSON file (docs/request-schema.md)")
    p.add_argument("-o", "--output", metavar="FILE", help="the image (.exr, or .png by its name)")
    p.add_argument("--png", metavar="FILE", help="also the PNG")
    waits(p)

    p = command("submit", cmd_submit, "submit a render request; print the answer (id, links) and return")
    p.add_argument("request", help="the request's JSON file")
    p.add_argument("--idempotency-key", metavar="KEY", help="makes a retried submission answer the same job")

    p = command("wait", cmd_wait, "wait for a render to end, showing its progress")
    p.add_argument("id")
    waits(p, submits=False)

    p = command("download", cmd_download, "download a render's image (progressive until it is done)")
    p.add_argument("id")
    p.add_argument("-o", "--output", metavar="FILE", help="the image (.exr, or .png by its name)")
    p.add_argument("--png", metavar="FILE", help="also the PNG")

    for name, handler, what in (("status", cmd_status, "print a render's status document"),
                                ("cancel", cmd_cancel, "cancel a render (or --purge: delete it)")):
        p = command(name, handler, what)
        p.add_argument("id")
        p.add_argument("--timelapse", action="store_true", help="ID is a timelapse's")
        if name == "cancel":
            p.add_argument("--purge", action="store_true", help="also delete the render's files and record")

    for name, handler, what in (("renders", cmd_renders, "list renders, newest first"),
                                ("timelapses", cmd_timelapses, "list timelapses, newest first")):
        p = command(name, handler, what)
        p.add_argument("--offset", type=int, default=0)
        p.add_argument("--limit", type=int, default=20)

    def sky_options(p):
        for name, kind, what in _SKY_OPTIONS:
            p.add_argument("--" + name, type=kind, help=what)
        p.add_argument("-q", "--query", action="append", metavar="NAME=VALUE",
                       help="any other query parameter of the route (repeatable)")

    p = command("sky", cmd_sky, "radiance in one direction from a cached LUT sky (JSON)")
    sky_options(p)
    p.add_argument("--view-zenith", type=float, required=True, help="degrees (0 up, 90 horizon)")
    p.add_argument("--view-azimuth", type=float, required=True, help="degrees clockwise from north")

    p = command("envmap", cmd_envmap, "a lat-long environment map of the sky (OpenEXR)")
    sky_options(p)
    p.add_argument("-o", "--output", required=True, metavar="FILE.exr")
    p.add_argument("--width", type=int, help="pixels, even (height = width / 2; server default 1024)")
    p.add_argument("--sun", choices=["disk", "none", "separate"], help="the sun disk in the pixels (default disk)")

    p = command("probe", cmd_probe, "radiance probe: spectral radiance in given directions (JSON)")
    p.add_argument("request", help="the probe's JSON file (api/examples/probe.json)")

    p = command("timelapse", cmd_timelapse, "submit a timelapse, wait, download frames, contact sheet, video")
    p.add_argument("request", help="the timelapse request's JSON file")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder for the files")
    p.add_argument("--no-exr", action="store_true", help="no EXR frames")
    p.add_argument("--no-png", action="store_true", help="no PNG frames")
    waits(p)

    command("workers", cmd_workers, "the connected workers (JSON)")

    p = command("assets", cmd_assets, "upload a mesh or cloud volume, show or download one")
    sub = p.add_subparsers(dest="assets_command", metavar="ACTION")
    sub.required = True
    up = sub.add_parser("upload", help="upload a mesh (obj, ply, stl, gltf, glb) or volume (vdb)")
    up.add_argument("file")
    up.add_argument("--format", choices=["obj", "ply", "stl", "gltf", "glb", "vdb"])
    up.add_argument("--grid", help="an OpenVDB file's float grid")
    get = sub.add_parser("get", help="an asset's metadata")
    get.add_argument("id")
    down = sub.add_parser("download", help="an asset's canonical file")
    down.add_argument("id")
    down.add_argument("-o", "--output", required=True, metavar="FILE")
    return parser


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        client = Client(args.server, args.token, timeout=args.timeout, busy_wait_s=args.busy_wait)
        return args.handler(client, args)
    except RenderFailed as e:
        _note("skyfarm: %s" % e)
        return EXIT_FAILED
    except SkyfarmError as e:
        if e.errors:
            for field_error in e.errors:
                _note("skyfarm: error: %s: %s" % (field_error.field or "(request)", field_error.message))
        else:
            _note("skyfarm: error: %s" % e)
        return EXIT_ERROR
    except OSError as e:  # a request file that cannot be read, an output that cannot be written
        _note("skyfarm: error: %s" % e)
        return EXIT_ERROR
    except KeyboardInterrupt:
        _note("\nskyfarm: interrupted (a submitted render goes on; `skyfarm cancel ID` stops it)")
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
