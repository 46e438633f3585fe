"""Scenes and read-out shared by the Cycles drivers (`cycles_calibrate.py`, `cycles_render.py`).

Every scene is in millimetres (`unit_settings.scale_length = 0.001`: one Blender unit is 1 mm; Cycles
itself reads lengths in Blender units, so radii and densities are in mm and mm⁻¹). Rendering is on
the CPU, with no denoising, no adaptive sampling and a fixed seed; pixels are read back as linear
floats from an OpenEXR file, so no view transform touches them.

- `slab`: a 100 × 100 × 50 mm block whose top face is z = 0, seen straight down by an orthographic
  camera over a 1 mm patch at its centre, under a uniform white sky of radiance 1. By reciprocity a
  pixel is the directional-hemispherical reflectance at normal incidence.
- `sphere`: a smooth-shaded sphere of radius 20 mm under the same sky, seen by an orthographic camera
  whose frame is the sphere's bounding square; pixels whose centre lies within 0.95 of the radius
  are averaged (the mean over the projected disc is the white-sky albedo).
"""

import os
import tempfile

import bpy
import numpy as np

SLAB_HALF_WIDTH_MM = 50.0
SLAB_THICKNESS_MM = 50.0
SPHERE_RADIUS_MM = 20.0
SPHERE_MASK = 0.95
SPHERE_SIDE_PX = 48


def reset(spp, px, seed=1, threads=2):
    """An empty scene in mm with Cycles on the CPU, `spp` samples, a `px` × `px` film."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.unit_settings.system = "METRIC"
    scene.unit_settings.scale_length = 0.001
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = seed
    c.filter_width = 0.01
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.blur_glossy = 0.0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.resolution_x = px
    scene.render.resolution_y = px
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    try:
        scene.view_settings.view_transform = "Standard"
    except TypeError:
        pass
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world
    return scene


def light_paths(scene, bounces):
    """Every bounce limit of Cycles at `bounces` (≤ 1024, its hard maximum)."""
    c = scene.cycles
    for name in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                 "volume_bounces", "transparent_max_bounces"):
        setattr(c, name, bounces)
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0


def camera(scene, height_mm, width_mm):
    """An orthographic camera `height_mm` above the origin looking straight down over `width_mm`."""
    data = bpy.data.cameras.new("camera")
    data.type = "ORTHO"
    data.ortho_scale = width_mm
    data.clip_start = 0.01
    data.clip_end = 10.0 * height_mm
    cam = bpy.data.objects.new("camera", data)
    cam.location = (0.0, 0.0, height_mm)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam


def box(name, half_x, half_y, z_bottom, z_top, material):
    """A closed box mesh with outward normals from the given extents (mm)."""
    xs, ys, zs = (-half_x, half_x), (-half_y, half_y), (z_bottom, z_top)
    verts = [(x, y, z) for z in zs for y in ys for x in xs]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def slab(scene, material):
    """The block under the camera, its top face at z = 0."""
    box("slab", SLAB_HALF_WIDTH_MM, SLAB_HALF_WIDTH_MM, -SLAB_THICKNESS_MM, 0.0, material)
    camera(scene, 10.0, 1.0)


def sphere(scene, material):
    """The smooth sphere under a camera framing it."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=SPHERE_RADIUS_MM)
    obj = bpy.context.active_object
    for poly in obj.data.polygons:
        poly.use_smooth = True
    obj.data.materials.append(material)
    camera(scene, 4.0 * SPHERE_RADIUS_MM, 2.0 * SPHERE_RADIUS_MM)


def render(scene):
    """Render and return the linear RGB pixels, shape (height, width, 3)."""
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "ZIP"
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "render.exr")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(path)
        w, h = img.size
        px = np.array(img.pixels[:], dtype=np.float64).reshape(h, w, img.channels)[:, :, :3]
        bpy.data.images.remove(img)
    return px


def disc_mask(px):
    """Pixels whose centre lies within `SPHERE_MASK` of the sphere's projected radius."""
    n = px.shape[0]
    centres = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    x, y = np.meshgrid(centres, centres)
    return x * x + y * y < SPHERE_MASK * SPHERE_MASK


def mean_and_stderr(pixels):
    """Per-channel mean of independent pixel estimates and its standard error."""
    flat = pixels.reshape(-1, pixels.shape[-1])
    return flat.mean(axis=0), flat.std(axis=0, ddof=1) / np.sqrt(flat.shape[0])
