"""Run by blender_grey_ball.py inside Blender, after scripts/blender/skyfarm_world.py
has set the World: a grey (albedo 0.5) Lambertian ball under an orthographic
camera looking straight down, rendered with Cycles on the CPU; the render is
read back (Blender's own EXR reader) and measured; the figures go to
$SKYFARM_DCC_RESULT as JSON for the driver to judge.

Measured:
  centroid_deg   direction of the luminance-weighted centroid of the ball's
                 pixels from its centre, in Blender's XY plane (0 = +X,
                 90 = +Y): the ball is brightest toward the sun
  top            mean scene-linear luminance (Rec.709) of the 4 x 4 pixels
                 at the ball's top (normals within 4 deg of +Z; the block is
                 symmetric, so the first-order change with tilt cancels)
  horizontal_illuminance_lux
                 the World map's cosine-weighted luminance over the upper
                 hemisphere, integrated here (pixel centres' cosines, each
                 pixel's exact solid angle), sun included; plus, for each
                 Sun lamp, 683 x strength x luminance of its colour x the
                 cosine of its direction from the zenith
  top_display    the same pixels in a PNG written with the scene's view
                 transform and exposure (0-1, display encoded)
"""
import json
import math
import os

import bpy

ALBEDO = 0.5
SIZE = 64                 # pixels
ORTHO_SCALE = 2.2         # the ball (radius 1) and a margin
REC709_Y = (0.2126, 0.7152, 0.0722)


def read_pixels(path):
    image = bpy.data.images.load(path, check_existing=False)
    w, h = image.size
    pixels = [0.0] * (w * h * 4)
    image.pixels.foreach_get(pixels)
    return image, w, h, pixels


def horizontal_illuminance(image):
    """Sum of Y cos(theta) dOmega over the map's upper hemisphere, with the
    cosine at each pixel's centre and dOmega the lat-long cell's exact solid
    angle (2 pi / W)(cos theta0 - cos theta1)."""
    w, h = image.size
    pixels = [0.0] * (w * h * 4)
    image.pixels.foreach_get(pixels)
    total = 0.0
    for y in range(h // 2):           # from the top (zenith) down to the horizon
        row = h - 1 - y               # Blender's rows run bottom-up
        t0, t1 = math.pi * y / h, math.pi * (y + 1) / h
        weight = math.cos(0.5 * (t0 + t1)) * 2.0 * math.pi / w * (math.cos(t0) - math.cos(t1))
        for i in range(row * w * 4, (row + 1) * w * 4, 4):
            total += weight * (REC709_Y[0] * pixels[i] + REC709_Y[1] * pixels[i + 1] + REC709_Y[2] * pixels[i + 2])
    return total


def build_scene(scene):
    for obj in list(bpy.data.objects):  # the startup scene's; not the World script's sun lamp
        if not obj.get("skyfarm"):
            bpy.data.objects.remove(obj, do_unlink=True)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=1.0, location=(0.0, 0.0, 0.0))
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    material = bpy.data.materials.new("grey")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.clear()
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (ALBEDO, ALBEDO, ALBEDO, 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambert
    output = nodes.new("ShaderNodeOutputMaterial")
    material.node_tree.links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])
    ball.data.materials.append(material)

    camera_data = bpy.data.cameras.new("top")
    camera_data.type = "ORTHO"
    camera_data.ortho_scale = ORTHO_SCALE
    camera = bpy.data.objects.new("top", camera_data)
    camera.location = (0.0, 0.0, 5.0)
    camera.rotation_euler = (0.0, 0.0, 0.0)  # looks down -Z; image right = +X, image up = +Y
    scene.collection.objects.link(camera)
    scene.camera = camera

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = int(os.environ.get("SKYFARM_DCC_SPP", "32"))
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.seed = 1
    scene.render.resolution_x = SIZE
    scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False


def main():
    out = os.environ["SKYFARM_DCC_OUT"]
    scene = bpy.context.scene
    build_scene(scene)
    exr = os.path.join(out, "ball.exr")
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = exr
    bpy.ops.render.render(write_still=True)
    # The same render, display-encoded with the scene's view transform and exposure.
    png = os.path.join(out, "ball.png")
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_depth = "16"
    bpy.data.images["Render Result"].save_render(png, scene=scene)

    _, w, h, pixels = read_pixels(exr)
    px = ORTHO_SCALE / SIZE
    sum_y = sum_x_y = sum_y_y = 0.0
    for j in range(h):        # from the bottom: Blender's rows
        for i in range(w):
            x, y = (i + 0.5 - w / 2) * px, (j + 0.5 - h / 2) * px
            if x * x + y * y > 0.95 ** 2:
                continue
            k = (j * w + i) * 4
            lum = REC709_Y[0] * pixels[k] + REC709_Y[1] * pixels[k + 1] + REC709_Y[2] * pixels[k + 2]
            sum_y += lum
            sum_x_y += lum * x
            sum_y_y += lum * y
    centroid_deg = math.degrees(math.atan2(sum_y_y, sum_x_y))
    block = [(j * w + i) * 4 for j in range(h // 2 - 2, h // 2 + 2) for i in range(w // 2 - 2, w // 2 + 2)]
    top = sum(REC709_Y[0] * pixels[k] + REC709_Y[1] * pixels[k + 1] + REC709_Y[2] * pixels[k + 2]
              for k in block) / len(block)
    _, _, _, display = read_pixels(png)
    top_display = sum(display[k + 1] for k in block) / len(block)

    world_image = next(n.image for n in scene.world.node_tree.nodes if n.type == "TEX_ENVIRONMENT")
    e_h = horizontal_illuminance(world_image)
    lamps = [obj for obj in scene.objects if obj.type == "LIGHT" and obj.data.type == "SUN"]
    for lamp in lamps:
        toward_sun = lamp.matrix_world.to_3x3().col[2].normalized()  # the lamp shines along -Z
        colour = sum(w * c for w, c in zip(REC709_Y, lamp.data.color))
        e_h += 683.0 * lamp.data.energy * colour * max(0.0, toward_sun.z)
    result = {
        "centroid_deg": centroid_deg,
        "top": top,
        "top_display": top_display,
        "horizontal_illuminance_lux": e_h,
        "sun_lamps": len(lamps),
        "script_horizontal_illuminance_lux": scene.get("skyfarm_horizontal_illuminance_lux"),
        "strength": next(n for n in scene.world.node_tree.nodes if n.type == "BACKGROUND").inputs["Strength"].default_value,
        "exposure": scene.view_settings.exposure,
        "view_transform": scene.view_settings.view_transform,
        "albedo": ALBEDO,
        "samples": scene.cycles.samples,
    }
    with open(os.environ["SKYFARM_DCC_RESULT"], "w") as f:
        json.dump(result, f, indent=1)


main()
