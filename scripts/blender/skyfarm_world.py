"""Sets Blender's World to a skyfarm sky, oriented and in physical units.

Run inside Blender (its own Python; the standard library only):

  blender -b -P scripts/blender/skyfarm_world.py -- --server http://127.0.0.1:8080 \\
      --lat 48.85 --lon 2.35 --time 2026-06-21T17:00:00+02:00 [--width 1024] [--save sky.blend]

Parameters (after Blender's `--`):
  --server URL      the skyfarm server (default http://127.0.0.1:8080)
  --token SECRET    its API token, when it has one
  --lat, --lon      the observer, degrees (+north, +east); default 0, 0
  --time ISO        the time, with its UTC offset (places the sun)
  --sun-zenith, --sun-azimuth
                    the sun's position instead (degrees; azimuth clockwise from north)
  --altitude M      observer altitude above the ground, m
  --aod X           aerosol optical depth at 550 nm
  --width N         the map's width in pixels (height N/2); default 1024
  --sun disk|lamp   disk (default): the sun disk in the map's pixels; lamp:
                    the map without it (sun=separate) and a Sun lamp from
                    the map's skyfarm:sun_* attributes instead (sharper
                    shadows, far less noise in Cycles)
  --exr PATH        where the map is kept (default: next to --save, else a
                    temporary folder); the image is packed into --save's file
  --strength S      the Background strength; default 1/683 (below)
  --exposure EV     the scene's exposure; default: the one that shows an 18 %
                    grey card lying flat under this sky as scene value 0.18
  --save PATH       save the .blend there

What it sets:
  The map (GET /v1/sky/envmap.exr: lat-long, linear Rec.709, cd/m^2; centre =
  north, right = east, top = zenith) in an Environment Texture node, as
  "Linear" (Rec.709, Blender's scene-linear space: no colour conversion).
  Orientation: Blender's Environment Texture puts the image's centre at +X
  and its right-hand quarter at -Y.  A Mapping node (Point) rotating the
  look-up direction by -90 deg about Z turns that so that north = +Y and
  east = +X (Z up), the convention of Blender's geographic add-ons (BlenderGIS,
  Blender-OSM: +Y = north).  The test Dcc.BlenderGreyBall checks it with
  morning and afternoon suns.
  Strength: the map is in cd/m^2 (lm m^-2 sr^-1).  Blender's lights are in
  watts by convention, a Sun lamp's strength being its irradiance in W/m^2;
  at the luminous efficacy of 555 nm, 683 lm/W, 1/683 turns the map into
  W m^-2 sr^-1 on the same scale, so a Sun lamp of E_v/683 W/m^2 next to this
  world is as bright as a sun giving E_v lux.
  Sun lamp (--sun lamp): strength = the disk's normal illuminance / 683
  (W/m^2), colour = the disk's mean Rec.709 radiance over its largest
  component (the strength carries that component), angle = the disk's
  angular diameter, pointing away from skyfarm:sun_direction (x east, y
  north, z up: Blender's axes after the rotation above).
  Exposure: scene values are then about 100-150 W/m^2 irradiance in
  daylight; exposure = log2(683 pi / E_h), with E_h the map's horizontal
  illuminance (lux, sun included, the lamp's too), brings a flat 18 % grey card to 0.18
  (mid-grey in the Filmic and Standard view transforms).
"""
import argparse
import math
import os
import struct
import sys
import tempfile
import urllib.error
import urllib.parse
import urllib.request

import bpy
import mathutils

LUMINOUS_EFFICACY_LM_PER_W = 683.0  # 555 nm (540 THz): the SI definition of the candela
# Rec.709 / sRGB luminance weights (ITU-R BT.709): the map's Y from its R, G, B.
REC709_Y = (0.2126, 0.7152, 0.0722)
# The Mapping node's rotation about Z that puts north at +Y and east at +X (see above).
NORTH_TO_PLUS_Y_DEG = -90.0


def parse_args(argv):
    p = argparse.ArgumentParser(prog="skyfarm_world.py", description="Blender World from a skyfarm sky")
    p.add_argument("--server", default="http://127.0.0.1:8080")
    p.add_argument("--token")
    p.add_argument("--lat", type=float)
    p.add_argument("--lon", type=float)
    p.add_argument("--time")
    p.add_argument("--sun-zenith", type=float)
    p.add_argument("--sun-azimuth", type=float)
    p.add_argument("--altitude", type=float)
    p.add_argument("--aod", type=float)
    p.add_argument("--width", type=int, default=1024)
    p.add_argument("--sun", choices=("disk", "lamp"), default="disk")
    p.add_argument("--exr")
    p.add_argument("--strength", type=float, default=1.0 / LUMINOUS_EFFICACY_LM_PER_W)
    p.add_argument("--exposure", type=float)
    p.add_argument("--save")
    args = p.parse_args(argv)
    if args.time is None and (args.sun_zenith is None or args.sun_azimuth is None):
        p.error("give --time, or --sun-zenith and --sun-azimuth")
    return args


def envmap_url(args):
    query = {"width": args.width}
    if args.sun == "lamp":
        query["sun"] = "separate"
    for key, value in (("lat", args.lat), ("lon", args.lon), ("time", args.time), ("altitude", args.altitude),
                       ("aod", args.aod), ("sun_zenith", args.sun_zenith), ("sun_azimuth", args.sun_azimuth)):
        if value is not None:
            query[key] = value
    return args.server.rstrip("/") + "/v1/sky/envmap.exr?" + urllib.parse.urlencode(query)


def fetch(url, path, token=None):
    request = urllib.request.Request(url)
    if token:
        request.add_header("Authorization", "Bearer " + token)
    try:
        with urllib.request.urlopen(request, timeout=300) as answer:
            data = answer.read()
    except urllib.error.HTTPError as e:
        sys.exit(f"skyfarm_world: {url}: {e.code} {e.read().decode(errors='replace')}")
    with open(path, "wb") as f:
        f.write(data)


def exr_attributes(path):
    """The string, double, float and int attributes of a single-part OpenEXR
    file's header (the file layout: magic, version, then for each attribute
    its name and type as NUL-terminated text, a little-endian int32 size and
    the value; a NUL ends the header).  bpy does not expose them."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x76\x2f\x31\x01":
        sys.exit(f"skyfarm_world: {path} is not an OpenEXR file")
    out, pos = {}, 8
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        name, kind = data[pos:name_end].decode(), data[name_end + 1:type_end].decode()
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        value = data[type_end + 5:type_end + 5 + size]
        pos = type_end + 5 + size
        if kind == "string":
            out[name] = value.decode(errors="replace")
        elif kind == "double":
            out[name] = struct.unpack("<d", value)[0]
        elif kind == "float":
            out[name] = struct.unpack("<f", value)[0]
        elif kind == "int":
            out[name] = struct.unpack("<i", value)[0]
    return out


def add_sun_lamp(scene, attributes):
    """A Sun lamp for the disk left out of the map (sun=separate); returns
    the horizontal illuminance it gives, lux."""
    rgb = [attributes[f"skyfarm:sun_disk_{c}"] for c in "RGB"]
    peak = max(rgb)
    direction = mathutils.Vector([float(v) for v in attributes["skyfarm:sun_direction"].split(",")]).normalized()
    data = bpy.data.lights.new("skyfarm sun", type="SUN")
    if peak > 0.0:
        data.color = [c / peak for c in rgb]
    # Per channel irradiance = radiance x solid angle, in Blender's W/m^2 (/ 683).
    data.energy = peak * attributes["skyfarm:sun_disk_solid_angle_sr"] / LUMINOUS_EFFICACY_LM_PER_W
    data.angle = math.radians(2.0 * attributes["skyfarm:sun_angular_radius_deg"])
    lamp = bpy.data.objects.new("skyfarm sun", data)
    lamp["skyfarm"] = True
    # A Sun lamp shines along its local -Z: point +Z at the sun.
    lamp.rotation_euler = direction.to_track_quat("Z", "Y").to_euler()
    scene.collection.objects.link(lamp)
    return attributes["skyfarm:sun_disk_illuminance_lux"] * max(0.0, direction.z)


def set_linear(image):
    # Blender 3.x calls Rec.709 scene-linear "Linear", 4.x "Linear Rec.709".
    for name in ("Linear", "Linear Rec.709"):
        try:
            image.colorspace_settings.name = name
            return
        except TypeError:
            continue


def latlong_horizontal_illuminance(image):
    """The map's horizontal illuminance, lux: sum over pixels of Y times the
    exact integral of cos(theta) over the pixel's cell (upper hemisphere),
    (2 pi / W) (sin^2 theta1 - sin^2 theta0) / 2 for the polar band
    [theta0, theta1]; the sun's pixels hold its exact energy (the server
    integrates the disk over them)."""
    w, h = image.size
    pixels = [0.0] * (w * h * 4)
    image.pixels.foreach_get(pixels)
    total = 0.0
    for row in range(h):  # Blender's rows run bottom-up
        y = h - 1 - row   # the map's row from the top (zenith)
        t0, t1 = math.pi * y / h, math.pi * (y + 1) / h
        if t0 >= math.pi / 2:
            continue
        t1 = min(t1, math.pi / 2)
        band = 2.0 * math.pi / w * 0.5 * (math.sin(t1) ** 2 - math.sin(t0) ** 2)
        base = row * w * 4
        s = 0.0
        for i in range(base, base + w * 4, 4):
            s += REC709_Y[0] * pixels[i] + REC709_Y[1] * pixels[i + 1] + REC709_Y[2] * pixels[i + 2]
        total += s * band
    return total


def build_world(scene, image, strength):
    world = scene.world or bpy.data.worlds.new("skyfarm sky")
    scene.world = world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    nodes.clear()
    coords = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(NORTH_TO_PLUS_Y_DEG))
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = image
    texture.projection = "EQUIRECTANGULAR"
    texture.interpolation = "Linear"
    background = nodes.new("ShaderNodeBackground")
    background.inputs["Strength"].default_value = strength
    output = nodes.new("ShaderNodeOutputWorld")
    links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    links.new(texture.outputs["Color"], background.inputs["Color"])
    links.new(background.outputs["Background"], output.inputs["Surface"])
    for i, node in enumerate((coords, mapping, texture, background, output)):
        node.location = (i * 250.0 - 600.0, 0.0)
    world["skyfarm_url"] = image.get("skyfarm_url", "")
    return world


def main(argv):
    args = parse_args(argv)
    url = envmap_url(args)
    if args.exr:
        path = os.path.abspath(args.exr)
    elif args.save:
        path = os.path.splitext(os.path.abspath(args.save))[0] + "_sky.exr"
    else:
        path = os.path.join(tempfile.mkdtemp(prefix="skyfarm-"), "sky.exr")
    fetch(url, path, args.token)
    image = bpy.data.images.load(path, check_existing=False)
    image.name = "skyfarm sky"
    set_linear(image)
    image["skyfarm_url"] = url
    scene = bpy.context.scene
    build_world(scene, image, args.strength)

    e_h = latlong_horizontal_illuminance(image)
    if args.sun == "lamp":
        e_h += add_sun_lamp(scene, exr_attributes(path))
    exposure = args.exposure
    if exposure is None:
        # An 18 % grey card lying flat: 0.18 E_h / pi cd/m^2, times the strength.
        exposure = math.log2(0.18 / (0.18 * e_h / math.pi * args.strength)) if e_h > 0 else 0.0
    scene.view_settings.exposure = exposure
    scene["skyfarm_horizontal_illuminance_lux"] = e_h
    print(f"skyfarm_world: {url}")
    print(f"skyfarm_world: map {image.size[0]}x{image.size[1]} in {path}; strength {args.strength:.6g}; "
          f"horizontal illuminance {e_h:.6g} lux; exposure {exposure:.3f} EV")
    if args.save:
        image.pack()
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.save))
        print(f"skyfarm_world: saved {os.path.abspath(args.save)}")


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
