# workbench_scene.py — Blender's Workbench renders the frames dermis-server's default range renders
# (run by bench/workbench_bench.sh inside `blender -b --python`, under Xvfb: Blender needs an X
# display for its GL context; on this kind of machine that is Mesa's llvmpipe, like dermis-server).
#
# Arguments after "--": GLB OUT_DIR CLIP FRAMES [SIZE]. Imports GLB (Blender's own glTF importer),
# plays clip CLIP at 50 frames/s (frames k = 0 … FRAMES−1 at k·0.02 s, `--frames 0:…:0.02`), and
# frames each one as core/camera.cpp does (yaw 0, pitch 10°, vertical field of view 30°, the posed
# bounds' sphere at radius / sin 15° · 1.02, re-framed every frame), then renders SIZE² PNGs with
# Workbench at its defaults (studio light, 8 anti-aliasing samples) and base-colour textures.
# Prints one line `WB_JSON {...}`: the render's seconds (import and Blender's start not counted)
# and the framing handler's share of them. It renders; it compares nothing.
import math
import sys
import time
import json

import numpy

if not hasattr(numpy, "bool"):  # Debian 12's numpy 1.24 against Blender 3.4's glTF importer
    numpy.bool = bool

import bpy
import mathutils

args = sys.argv[sys.argv.index("--") + 1:] + ["1024"]  # SIZE is optional
glb, out, clip = args[:3]
frames, size = int(args[3]), int(args[4])
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 50  # before the import, which keys the clip at the scene's rate
bpy.ops.import_scene.gltf(filepath=glb)
action = bpy.data.actions.get(clip) or next((a for a in bpy.data.actions if clip in a.name), None)
if action is None:
    raise SystemExit(f"workbench_scene: no clip named {clip!r}")
for ob in scene.objects:
    if ob.type == "ARMATURE":
        ob.animation_data_create().action = action
scene.frame_start, scene.frame_end = 0, frames - 1

cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(cam)
scene.camera = cam
cam.data.sensor_fit = "VERTICAL"
cam.data.angle = math.radians(30)
pitch = math.radians(10)
framing_seconds = [0.0]


def frame_camera(scene, depsgraph=None):
    """Frames the posed mesh like dermis's auto camera (glTF +Z is Blender's −Y)."""
    t = time.time()
    dg = depsgraph or bpy.context.evaluated_depsgraph_get()
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    for ob in scene.objects:
        if ob.type != "MESH":
            continue
        ev = ob.evaluated_get(dg)
        mesh = ev.to_mesh()
        for v in mesh.vertices:
            p = ev.matrix_world @ v.co
            for i in range(3):
                lo[i], hi[i] = min(lo[i], p[i]), max(hi[i], p[i])
        ev.to_mesh_clear()
    lo, hi = mathutils.Vector(lo), mathutils.Vector(hi)
    centre, radius = (lo + hi) / 2, (hi - lo).length / 2
    d = radius / math.sin(math.radians(15)) * 1.02
    cam.location = centre + mathutils.Vector((0, -d * math.cos(pitch), d * math.sin(pitch)))
    cam.rotation_euler = (math.radians(90) - pitch, 0, 0)
    framing_seconds[0] += time.time() - t


bpy.app.handlers.frame_change_post.append(frame_camera)
scene.render.engine = "BLENDER_WORKBENCH"
scene.render.resolution_x = scene.render.resolution_y = size
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "PNG"
scene.render.filepath = out.rstrip("/") + "/f_"
scene.display.shading.light = "STUDIO"
scene.display.shading.color_type = "TEXTURE"
t0 = time.time()
bpy.ops.render.render(animation=True)
seconds = time.time() - t0
print("WB_JSON " + json.dumps({"frames": frames, "seconds": round(seconds, 3),
                               "ms_per_frame": round(seconds / frames * 1000, 1),
                               "framing_seconds": round(framing_seconds[0], 3),
                               "aa_samples": scene.display.render_aa, "blender": bpy.app.version_string}))
