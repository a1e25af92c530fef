# Physically based test scenes for softsight (tests/pbr/README.md).
#
# Run by scripts/pbr/render.sh, not by hand:
#   blender -b --factory-startup -P scripts/pbr/scene.py -- --scene bench --out /tmp/pbr/bench
# Builds one scene from nothing (procedural geometry and textures, no downloaded assets), renders
# its frames as PNG into OUT/frames/ and writes OUT/truth.json: per frame and marker the
# projection of the marker's apex (the centre of its domed top face) by the scene's camera, the
# fraction of its top face that the camera sees, and the scene's settings. Sensor noise, the codec
# and the CSV/YAML files are added afterwards by scripts/pbr/post.py (plain Python with OpenCV),
# so that Blender is needed only to make the pictures.
#
# Units: metres in Blender; sizes below are written in millimetres (MM) for readability.
# Conventions of the truth: pixel (row i, column j) has its centre at x = j, y = i; x right, y down.
import argparse
import json
import math
import os
import sys
import time

import bmesh
import bpy
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

MM = 0.001

# ---------------------------------------------------------------------------------------------
# The scene library. Every scene is the same actuator on the same kind of bench; what varies is
# what makes tracking hard on real footage (light, clutter, occlusion, blur, colours, codec).
#   layout 'side': the actuator bends in a vertical plane, the camera looks at its side over the
#                  bench, a pegboard behind; 'top': it lies on the bench and bends in the bench's
#                  plane, the camera looks down on it, the wooden bench is the background.
#   bend: (start deg, peak deg, frames to the peak, frames held there) of the bend angle; the angle
#         rises and falls with a smooth (cosine) profile, so speed peaks mid-way.
# ---------------------------------------------------------------------------------------------
RGB = dict(red=(0.62, 0.035, 0.04), green=(0.05, 0.38, 0.09), blue=(0.035, 0.09, 0.50),
           yellow=(0.80, 0.60, 0.03), magenta=(0.55, 0.04, 0.38), white=(0.85, 0.85, 0.83),
           black=(0.02, 0.02, 0.022), orange=(0.80, 0.20, 0.02), cyan=(0.02, 0.42, 0.52),
           purple=(0.22, 0.05, 0.48))
# Pale (pastel) pigments, named by hue as a user's pick names them: 8-bit saturation ~60-90 after
# the camera's gamma, where the saturated ones above are ~200.
RGB_PALE = dict(red=(0.80, 0.30, 0.33), green=(0.34, 0.66, 0.30), blue=(0.30, 0.42, 0.80))

SCENES = {
    'bench': dict(
        what='ordinary lab bench, cold (6500 K) light from the front and above, pegboard behind',
        layout='side', light='cold_front', markers=['red', 'blue', 'green'],
        bend=(5, 60, 15, 3), frames=36, codec='mjpg', noise=2.0, seed=1),
    'side': dict(
        what='dim warm (2700 K) light from one side with a highlight on each dome, dark shadows',
        layout='side', light='warm_side', markers=['red', 'blue', 'green'],
        bend=(5, 80, 15, 3), frames=36, codec='mjpg', noise=4.0, seed=2),
    'distractors': dict(
        what='red screwdriver, blue and green caps and a red cap on the bench, of the markers\' colours',
        layout='side', light='cold_front', markers=['red', 'blue', 'green'], distractors=True,
        bend=(5, 80, 15, 3), frames=36, codec='mjpg', noise=2.5, seed=3),
    'finger': dict(
        what='a finger comes down in front of the middle (blue) marker, covers it, and leaves',
        layout='side', light='neutral_top', markers=['red', 'blue', 'green'], finger=True,
        bend=(5, 50, 15, 3), frames=36, codec='mjpg', noise=2.5, seed=4),
    'fastblur': dict(
        what='fast bending (the tip moves 20-30 px a frame), motion blur, H.264',
        layout='side', light='cold_front', markers=['red', 'blue', 'green'],
        bend=(5, 125, 12, 2), frames=36, codec='h264', noise=3.0, seed=5, shutter=0.5),
    'wedge': dict(
        what='4-segment wedge actuator lying on a wooden bench, 5 markers in 5 colours '
             '(red, yellow, green, blue, magenta), seen from above',
        layout='top', light='neutral_top', markers=['red', 'yellow', 'green', 'blue', 'magenta'],
        wedge=True, bend=(5, 100, 15, 3), frames=36, codec='mjpg', noise=2.0, seed=6),
    'whitedots': dict(
        what='white domed dots on a dark grey actuator in front of the pegboard',
        layout='side', light='cold_front', markers=['white', 'white', 'white'], dark=True,
        bend=(5, 80, 15, 3), frames=36, codec='mjpg', noise=2.0, seed=7),
    'pale': dict(
        what='pale (pastel) glossy domes with sharp highlights, cold front light',
        layout='side', light='cold_front', markers=['red', 'blue', 'green'], pale=True, gloss=True,
        bend=(5, 80, 15, 3), frames=36, codec='mjpg', noise=2.5, seed=8),
    'stickers': dict(
        what='flat elongated stickers (2:1, along the body) that turn with the bending tip, warm side light',
        layout='side', light='warm_side', markers=['red', 'blue', 'green'], aspect=2.0, flat=True,
        s_mm=[14, 50, 86],
        bend=(5, 100, 15, 3), frames=36, codec='mjpg', noise=3.0, seed=9),
    'hard': dict(
        what='everything at once: dim warm side light, distractors of the markers\' colours, a finger '
             'over the middle marker, a fast bend with motion blur',
        layout='side', light='warm_side', markers=['red', 'blue', 'green'], distractors=True,
        finger=True, bend=(5, 110, 12, 2), frames=36, codec='mjpg', noise=4.0, seed=10, shutter=0.5),
    'wedgehard': dict(
        what='the 5-colour wedge from above under the warm side lamp, a finger over its second '
             'marker, a fast bend with motion blur',
        layout='top', light='warm_side', markers=['red', 'yellow', 'green', 'blue', 'magenta'],
        wedge=True, finger=True, bend=(5, 110, 12, 2), frames=36, codec='mjpg', noise=4.0,
        seed=11, shutter=0.5),
    'blackdots': dict(
        what='flat black ink dots on the milky actuator under the warm side lamp, whose ribs cast '
             'shadows as dark as the dots',
        layout='side', light='warm_side', markers=['black', 'black', 'black'], flat=True,
        bend=(5, 90, 15, 3), frames=36, codec='mjpg', noise=3.0, seed=12),
    'mat': dict(
        what='orange, cyan and purple markers on the actuator lying on a green self-healing cutting '
             'mat (white 10 mm grid), seen from above',
        layout='top', light='neutral_top', markers=['orange', 'cyan', 'purple'], bench='mat',
        bend=(5, 90, 15, 3), frames=36, codec='mjpg', noise=2.5, seed=13),
    'hd': dict(
        what='a 1280x720 webcam recording in H.264: the bench under the ceiling panel, a fast bend '
             'to 110 deg (the tip moves up to 45 px a frame) with motion blur',
        layout='side', light='cold_front', markers=['red', 'blue', 'green'], size=(1280, 720),
        bend=(5, 110, 12, 2), frames=36, codec='h264', noise=3.0, seed=14, shutter=0.5),
    'darkdomes': dict(
        what='orange, cyan and purple domes on a dark grey actuator under the dim warm side lamp, '
             'a fast blurred bend',
        layout='side', light='warm_side', markers=['orange', 'cyan', 'purple'], dark=True,
        bend=(5, 100, 12, 2), frames=36, codec='mjpg', noise=4.0, seed=21, shutter=0.5),
    'wood960': dict(
        what='yellow, blue and red domes on the actuator lying on the wooden bench (yellow the '
             'wood\'s hue), seen from above under the ceiling panel, 960x540 H.264',
        layout='top', light='cold_front', markers=['yellow', 'blue', 'red'], size=(960, 540),
        bend=(5, 90, 15, 3), frames=36, codec='h264', noise=3.0, seed=22, shutter=0.5),
}

LENGTH = 100 * MM        # actuator length from the clamp to the tip
BODY_H = 14 * MM         # height of the solid strip carrying the markers (in the bending plane)
DEPTH = 14 * MM          # thickness towards the camera (the markers sit on the +depth face)
RIB_H = 6 * MM           # how far the chambers (ribs) stand out on the convex side
DOME_R = 4.5 * MM        # marker radius (9 mm discs, as the lab's)
DOME_H = 1.6 * MM        # height of the dome above the face
HFOV = 55.0              # camera's horizontal field of view, degrees
WIDTH, HEIGHT, FPS = 640, 480, 30  # a scene's `size` replaces the first two


def parse():
    argv = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []
    p = argparse.ArgumentParser()
    p.add_argument('--scene', required=True, choices=sorted(SCENES))
    p.add_argument('--out', required=True)
    p.add_argument('--samples', type=int, default=12)
    p.add_argument('--frames', type=int, help='render only the first N frames (timing)')
    p.add_argument('--threads', type=int, default=1)
    p.add_argument('--look', type=int, help='render only this frame, whole, as look.png (preview)')
    p.add_argument('--scale', type=int, default=100, help='resolution percentage (timing)')
    return p.parse_args(argv)


# --------------------------------- materials (procedural) ------------------------------------
def node_mat(name):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    bsdf = nt.nodes['Principled BSDF']
    bsdf.subsurface_method = 'BURLEY'   # the cheapest subsurface model: enough at this scale
    return m, nt, bsdf


def silicone(dark):
    # Cast silicone (Ecoflex / Dragon Skin): milky and translucent, so the light scatters under the
    # surface (subsurface scattering over a few mm); the dark variant is pigmented black silicone.
    m, nt, b = node_mat('silicone')
    if dark:
        b.inputs['Base Color'].default_value = (0.035, 0.035, 0.04, 1)
        b.inputs['Subsurface'].default_value = 0.0
        b.inputs['Roughness'].default_value = 0.45
    else:
        b.inputs['Base Color'].default_value = (0.70, 0.73, 0.71, 1)
        b.inputs['Subsurface'].default_value = 0.6
        b.inputs['Subsurface Color'].default_value = (0.85, 0.88, 0.85, 1)
        b.inputs['Subsurface Radius'].default_value = (3 * MM, 2.5 * MM, 2 * MM)
        b.inputs['Roughness'].default_value = 0.35
    b.inputs['Specular'].default_value = 0.35
    return m


def marker_rgb(cfg, colour):
    return (RGB_PALE if cfg.get('pale') else RGB)[colour]


def marker_mat(cfg, colour):
    # Pigmented silicone dome: saturated, a little glossy so the light shows as a highlight
    # (`gloss`: a polished one, with a small sharp highlight).
    m, nt, b = node_mat(f'marker_{colour}')
    rgb = marker_rgb(cfg, colour)
    b.inputs['Base Color'].default_value = (*rgb, 1)
    b.inputs['Subsurface'].default_value = 0.15
    b.inputs['Subsurface Color'].default_value = (*rgb, 1)
    b.inputs['Subsurface Radius'].default_value = (0.6 * MM, 0.4 * MM, 0.3 * MM)
    b.inputs['Roughness'].default_value = 0.08 if cfg.get('gloss') else 0.22
    b.inputs['Specular'].default_value = 0.8 if cfg.get('gloss') else 0.5
    return m


def plain_mat(name, rgb, rough=0.5, metal=0.0, spec=0.5):
    m, nt, b = node_mat(name)
    b.inputs['Base Color'].default_value = (*rgb, 1)
    b.inputs['Roughness'].default_value = rough
    b.inputs['Metallic'].default_value = metal
    b.inputs['Specular'].default_value = spec
    return m


def wood_mat():
    # Wood: wave bands distorted by noise (growth rings seen lengthwise), a fine noise for pores,
    # mapped through a light/dark brown ramp; bump from the same pattern.
    m, nt, b = node_mat('wood')
    N = nt.nodes
    tc = N.new('ShaderNodeTexCoord')
    mp = N.new('ShaderNodeMapping')
    mp.inputs['Scale'].default_value = (1.0, 6.0, 1.0)   # long grain along x
    wave = N.new('ShaderNodeTexWave')
    wave.wave_type = 'BANDS'
    wave.bands_direction = 'Y'
    wave.inputs['Scale'].default_value = 4.0
    wave.inputs['Distortion'].default_value = 6.0
    wave.inputs['Detail'].default_value = 3.0
    noise = N.new('ShaderNodeTexNoise')
    noise.inputs['Scale'].default_value = 300.0
    mix = N.new('ShaderNodeMixRGB')
    mix.blend_type = 'MULTIPLY'
    mix.inputs['Fac'].default_value = 0.25
    ramp = N.new('ShaderNodeValToRGB')
    ramp.color_ramp.elements[0].color = (0.30, 0.16, 0.07, 1)
    ramp.color_ramp.elements[1].color = (0.62, 0.40, 0.20, 1)
    bump = N.new('ShaderNodeBump')
    bump.inputs['Strength'].default_value = 0.1
    L = nt.links
    L.new(tc.outputs['Object'], mp.inputs['Vector'])
    L.new(mp.outputs['Vector'], wave.inputs['Vector'])
    L.new(wave.outputs['Fac'], ramp.inputs['Fac'])
    L.new(ramp.outputs['Color'], mix.inputs['Color1'])
    L.new(noise.outputs['Color'], mix.inputs['Color2'])
    L.new(mix.outputs['Color'], b.inputs['Base Color'])
    L.new(wave.outputs['Fac'], bump.inputs['Height'])
    L.new(bump.outputs['Normal'], b.inputs['Normal'])
    b.inputs['Roughness'].default_value = 0.55
    return m


def cutting_mat():
    # A green self-healing cutting mat: a slightly mottled matte green with thin light lines every
    # 10 mm (world x and y), as on many lab benches.
    m, nt, b = node_mat('cutting_mat')
    N, L = nt.nodes, nt.links
    geo = N.new('ShaderNodeNewGeometry')
    sep = N.new('ShaderNodeSeparateXYZ')
    L.new(geo.outputs['Position'], sep.inputs['Vector'])
    lines = []
    for axis in ('X', 'Y'):
        scale = N.new('ShaderNodeMath')
        scale.operation = 'MULTIPLY'
        scale.inputs[1].default_value = 100.0          # one cell per 10 mm
        L.new(sep.outputs[axis], scale.inputs[0])
        frac = N.new('ShaderNodeMath')
        frac.operation = 'FRACT'
        L.new(scale.outputs[0], frac.inputs[0])
        line = N.new('ShaderNodeMath')
        line.operation = 'LESS_THAN'
        line.inputs[1].default_value = 0.05            # 0.5 mm wide
        L.new(frac.outputs[0], line.inputs[0])
        lines.append(line)
    either = N.new('ShaderNodeMath')
    either.operation = 'MAXIMUM'
    L.new(lines[0].outputs[0], either.inputs[0])
    L.new(lines[1].outputs[0], either.inputs[1])
    noise = N.new('ShaderNodeTexNoise')
    noise.inputs['Scale'].default_value = 80.0
    mottle = N.new('ShaderNodeMixRGB')
    mottle.blend_type = 'MULTIPLY'
    mottle.inputs['Fac'].default_value = 0.15
    mottle.inputs['Color1'].default_value = (0.04, 0.20, 0.10, 1)
    L.new(noise.outputs['Color'], mottle.inputs['Color2'])
    mix = N.new('ShaderNodeMixRGB')
    mix.inputs['Color2'].default_value = (0.60, 0.68, 0.62, 1)
    L.new(either.outputs[0], mix.inputs['Fac'])
    L.new(mottle.outputs['Color'], mix.inputs['Color1'])
    L.new(mix.outputs['Color'], b.inputs['Base Color'])
    b.inputs['Roughness'].default_value = 0.7
    return m


def pegboard_mat():
    # Hardboard pegboard: tan fibre board with a fine noise, dark holes on a 25 mm grid (a Voronoi
    # texture with no randomness is a regular grid; its F1 distance thresholded gives the holes).
    m, nt, b = node_mat('pegboard')
    N, L = nt.nodes, nt.links
    tc = N.new('ShaderNodeTexCoord')
    vor = N.new('ShaderNodeTexVoronoi')
    vor.voronoi_dimensions = '3D'
    vor.inputs['Scale'].default_value = 40.0          # 1 / 25 mm
    vor.inputs['Randomness'].default_value = 0.0
    holes = N.new('ShaderNodeValToRGB')
    holes.color_ramp.interpolation = 'CONSTANT'
    holes.color_ramp.elements[0].color = (0.015, 0.012, 0.01, 1)
    holes.color_ramp.elements[1].position = 0.13
    holes.color_ramp.elements[1].color = (1, 1, 1, 1)
    noise = N.new('ShaderNodeTexNoise')
    noise.inputs['Scale'].default_value = 150.0
    noise.inputs['Detail'].default_value = 6.0
    fibre = N.new('ShaderNodeValToRGB')
    fibre.color_ramp.elements[0].color = (0.42, 0.30, 0.19, 1)
    fibre.color_ramp.elements[1].color = (0.58, 0.44, 0.30, 1)
    mix = N.new('ShaderNodeMixRGB')
    mix.blend_type = 'MULTIPLY'
    mix.inputs['Fac'].default_value = 1.0
    L.new(tc.outputs['Object'], vor.inputs['Vector'])
    L.new(tc.outputs['Object'], noise.inputs['Vector'])
    L.new(vor.outputs['Distance'], holes.inputs['Fac'])
    L.new(noise.outputs['Fac'], fibre.inputs['Fac'])
    L.new(fibre.outputs['Color'], mix.inputs['Color1'])
    L.new(holes.outputs['Color'], mix.inputs['Color2'])
    L.new(mix.outputs['Color'], b.inputs['Base Color'])
    b.inputs['Roughness'].default_value = 0.8
    return m


def skin_mat():
    m, nt, b = node_mat('skin')
    b.inputs['Base Color'].default_value = (0.80, 0.52, 0.40, 1)
    b.inputs['Subsurface'].default_value = 0.3
    b.inputs['Subsurface Color'].default_value = (0.9, 0.4, 0.3, 1)
    b.inputs['Subsurface Radius'].default_value = (3 * MM, 1.2 * MM, 0.8 * MM)
    b.inputs['Roughness'].default_value = 0.45
    return m


# --------------------------------------- geometry --------------------------------------------
def add_box(bm, x0, x1, y0, y1, z0, z1, nx=1, taper=0.0):
    """A box from x0 to x1 cut into nx slices along x (so that it bends smoothly); `taper` shrinks
    the face at y0 along x by that fraction on each side (a wedge-shaped chamber)."""
    rings = []
    for i in range(nx + 1):
        t = i / nx
        x = x0 + (x1 - x0) * t
        xs = x0 + (x1 - x0) * (taper + (1 - 2 * taper) * t)   # x on the tapered face
        rings.append([bm.verts.new((xs, y0, z0)), bm.verts.new((x, y1, z0)),
                      bm.verts.new((x, y1, z1)), bm.verts.new((xs, y0, z1))])
    for a, b in zip(rings, rings[1:]):
        for k in range(4):
            bm.faces.new((a[k], b[k], b[(k + 1) % 4], a[(k + 1) % 4]))
    bm.faces.new(tuple(reversed(rings[0])))
    bm.faces.new(tuple(rings[-1]))


def actuator_mesh(wedge):
    """The actuator straight, in its own frame: x from the clamp (0) to the tip (LENGTH), y across in
    the bending plane (it bends towards +y: the solid strip is the inner side, the chambers stand
    out on -y), z towards the camera. Slices every 1 mm so the bend is smooth."""
    bm = bmesh.new()
    add_box(bm, 0, LENGTH, 0, BODY_H, -DEPTH / 2, DEPTH / 2, nx=100)
    if wedge:   # four large wedge-shaped chambers
        n, gap = 4, 3 * MM
        pitch = (LENGTH - 8 * MM) / n
        for k in range(n):
            x0 = 6 * MM + k * pitch
            add_box(bm, x0, x0 + pitch - gap, -2.2 * RIB_H, 0, -DEPTH / 2 + MM, DEPTH / 2 - MM,
                    nx=12, taper=0.12)
    else:       # PneuNet ribs: 5 mm chambers, 3 mm gaps
        x0 = 5 * MM
        while x0 + 5 * MM <= LENGTH - 3 * MM:
            add_box(bm, x0, x0 + 5 * MM, -RIB_H, 0, -DEPTH / 2 + 0.8 * MM, DEPTH / 2 - 0.8 * MM, nx=3)
            x0 += 8 * MM
    bmesh.ops.recalc_face_normals(bm, faces=bm.faces)
    me = bpy.data.meshes.new('actuator')
    bm.to_mesh(me)
    bm.free()
    return me


def markers_mesh(positions, colours, aspect=1.0, height=DOME_H):
    """Domes (flattened half spheres) on the actuator's +z face at the given arc positions. Their
    apex vertex (the centre of the top face) and a ring of top-face points are returned for the
    truth. Two loose vertices at x=0 and x=LENGTH give this mesh the same extent along x as the
    actuator, so the same Simple Deform bend moves the domes exactly with the face under them
    (loose vertices are not rendered)."""
    bm = bmesh.new()
    info = []
    for k, (s, c) in enumerate(zip(positions, colours)):
        res = bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=1.0)
        verts = res['verts']
        lower = [v for v in verts if v.co.z < -1e-6]
        bmesh.ops.delete(bm, geom=lower, context='VERTS')
        verts = [v for v in verts if v.is_valid]
        for v in verts:
            v.co = Vector((s + v.co.x * DOME_R * aspect, BODY_H / 2 + v.co.y * DOME_R, DEPTH / 2 + v.co.z * height))
        for f in {f for v in verts for f in v.link_faces}:
            f.material_index = k
            f.smooth = True
        info.append(dict(s=s, colour=c))
    bm.verts.new((0, BODY_H / 2, 0))
    bm.verts.new((LENGTH, BODY_H / 2, 0))
    bm.verts.ensure_lookup_table()
    # apex = highest z per dome; top-face points = vertices within 0.6 R of the apex (around it)
    for k, d in enumerate(info):
        mine = [v for v in bm.verts if abs(v.co.x - d['s']) <= DOME_R * aspect * 1.01
                and v.co.z > DEPTH / 2 - 1e-6 and abs(v.co.y - BODY_H / 2) <= DOME_R * 1.01]
        apex = max(mine, key=lambda v: v.co.z)
        d['apex'] = apex.index
        d['top'] = [v.index for v in mine
                    if (Vector(((v.co.x - apex.co.x) / aspect, v.co.y - apex.co.y))).length <= 0.65 * DOME_R]
        d['rim'] = [v.index for v in mine if abs(v.co.z - DEPTH / 2) < 1e-7]
    me = bpy.data.meshes.new('markers')
    bm.to_mesh(me)
    bm.free()
    return me, info


def bend_modifier(obj):
    mod = obj.modifiers.new('bend', 'SIMPLE_DEFORM')
    mod.deform_method = 'BEND'
    mod.deform_axis = 'Z'      # bends the x axis towards +y: a constant-curvature arc
    return mod


def bend_angle(cfg, f):
    """The bend angle (deg) at frame f: hold, rise with a cosine profile, hold, fall, hold."""
    a0, a1, rise, hold = cfg['bend']
    t0 = 3
    if f < t0:
        return a0
    f -= t0
    if f < rise:
        return a0 + (a1 - a0) * (1 - math.cos(math.pi * f / rise)) / 2
    f -= rise
    if f < hold:
        return a1
    f -= hold
    if f < rise:
        return a1 - (a1 - a0) * (1 - math.cos(math.pi * f / rise)) / 2
    return a0


def cylinder(name, r, depth, loc, rot, mat, verts=32):
    bpy.ops.mesh.primitive_cylinder_add(vertices=verts, radius=r, depth=depth, location=loc, rotation=rot)
    o = bpy.context.object
    o.name = name
    o.data.materials.append(mat)
    bpy.ops.object.shade_smooth()
    return o


def build(cfg):
    scene = bpy.context.scene
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    side = cfg['layout'] == 'side'
    n = len(cfg['markers'])
    # markers evenly along the actuator: 3 at 12/52/92 mm as the lab's, 5 at 10..94 mm
    s_mm = cfg.get('s_mm') or ([12, 52, 92] if n == 3 else [10 + 21 * k for k in range(n)])

    act = bpy.data.objects.new('actuator', actuator_mesh(cfg.get('wedge', False)))
    act.data.materials.append(silicone(cfg.get('dark', False)))
    for p in act.data.polygons:
        p.use_smooth = False
    bev = act.modifiers.new('round', 'BEVEL')      # silicone edges are rounded, not sharp
    bev.width = 0.7 * MM
    bev.segments = 2
    bev.limit_method = 'ANGLE'
    # `flat`: stickers 0.3 mm thick (their top face is still the highest point at the centre)
    mk_me, info = markers_mesh([s * MM for s in s_mm], cfg['markers'], cfg.get('aspect', 1.0),
                               0.3 * MM if cfg.get('flat') else DOME_H)
    mk = bpy.data.objects.new('markers', mk_me)
    for c in cfg['markers']:
        mk.data.materials.append(marker_mat(cfg, c))
    for o in (act, mk):
        scene.collection.objects.link(o)
        bend_modifier(o)
        if side:   # bending plane vertical (local y -> up), markers face the camera (local z -> -y)
            o.rotation_euler = (math.radians(90), 0, 0)
            o.location = (0, 0, 55 * MM)
        else:      # lying on its side on the bench, markers up, bending in the bench's plane
            o.location = (0, -BODY_H / 2, DEPTH / 2 + 0.2 * MM)
    # the bend angle, keyed on every frame so the motion between frames (motion blur) follows it
    frames = cfg['frames']
    for f in range(frames + 1):
        ang = math.radians(bend_angle(cfg, f))
        for o in (act, mk):
            o.modifiers['bend'].angle = ang
            o.modifiers['bend'].keyframe_insert('angle', frame=f)

    # bench, clamp, background
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(40 * MM, 60 * MM, 0))
    bench = bpy.context.object
    bench.scale = (0.8, 0.6, 1)
    bench.data.materials.append(cutting_mat() if cfg.get('bench') == 'mat' else wood_mat())
    metal = plain_mat('clamp', (0.12, 0.12, 0.13), rough=0.35, metal=0.7)
    if side:
        bpy.ops.mesh.primitive_cube_add(size=1, location=(-12 * MM, 0, 37 * MM))
        clamp = bpy.context.object
        clamp.scale = (26 * MM, 30 * MM, 74 * MM)
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(40 * MM, 130 * MM, 0.2), rotation=(math.radians(90), 0, 0))
        peg = bpy.context.object
        peg.scale = (0.8, 0.42, 1)
        peg.data.materials.append(pegboard_mat())
    else:
        bpy.ops.mesh.primitive_cube_add(size=1, location=(-12 * MM, 0, 12 * MM))
        clamp = bpy.context.object
        clamp.scale = (26 * MM, 34 * MM, 24 * MM)
    clamp.data.materials.append(metal)
    clamp.modifiers.new('round', 'BEVEL').width = 1.5 * MM

    if cfg.get('distractors'):
        # a red-handled screwdriver and caps of the markers' colours, on the bench in view
        red = plain_mat('d_red', RGB['red'], rough=0.3)
        grn = plain_mat('d_green', RGB['green'], rough=0.35)
        blu = plain_mat('d_blue', RGB['blue'], rough=0.35)
        steel = plain_mat('steel', (0.7, 0.7, 0.72), rough=0.25, metal=1.0)
        cylinder('screwdriver_handle', 7 * MM, 60 * MM, (75 * MM, -45 * MM, 7 * MM), (0, math.radians(90), math.radians(-15)), red, 8)
        cylinder('screwdriver_shaft', 2.5 * MM, 70 * MM, (135 * MM, -61 * MM, 6 * MM), (0, math.radians(90), math.radians(-15)), steel)
        cylinder('cap_blue', 12 * MM, 9 * MM, (10 * MM, -35 * MM, 4.5 * MM), (0, 0, 0), blu)
        cylinder('cap_green', 10 * MM, 14 * MM, (150 * MM, 10 * MM, 7 * MM), (0, 0, 0), grn)
        cylinder('cap_red', 9 * MM, 12 * MM, (-45 * MM, 20 * MM, 6 * MM), (0, 0, 0), red)
        # a blue and a green part hanging on the pegboard, near where the markers pass
        bpy.ops.mesh.primitive_cube_add(size=1, location=(120 * MM, 120 * MM, 110 * MM))
        b = bpy.context.object
        b.scale = (14 * MM, 8 * MM, 30 * MM)
        b.data.materials.append(blu)
        bpy.ops.mesh.primitive_uv_sphere_add(radius=8 * MM, location=(-30 * MM, 118 * MM, 95 * MM))
        g = bpy.context.object
        g.data.materials.append(grn)
        bpy.ops.object.shade_smooth()

    finger = None
    if cfg.get('finger'):
        # a finger: a capsule (sphere stretched along its axis) coming down from above in front of
        # the middle marker, pausing over it, and leaving again
        bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=1.0)
        finger = bpy.context.object
        finger.name = 'finger'
        finger.scale = (10 * MM, 10 * MM, 48 * MM)
        finger.rotation_euler = (0, math.radians(8), 0)
        finger.data.materials.append(skin_mat())
        bpy.ops.object.shade_smooth()

    # camera
    cam_data = bpy.data.cameras.new('cam')
    cam_data.sensor_fit = 'HORIZONTAL'
    cam_data.sensor_width = 36.0
    cam_data.lens = 18.0 / math.tan(math.radians(HFOV / 2))
    cam = bpy.data.objects.new('cam', cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    if side:
        cam.location = (50 * MM, -300 * MM, 95 * MM)
        target = Vector((50 * MM, 0, 80 * MM))
        d = target - cam.location
        cam.rotation_euler = d.to_track_quat('-Z', 'Y').to_euler()
    else:       # from above, tilted 10 deg, image x along the actuator and image up = +y
        target = Vector((45 * MM, 30 * MM, 0))
        tilt = math.radians(10)
        cam.location = target + Vector((0, -math.sin(tilt), math.cos(tilt))) * 300 * MM
        cam.rotation_euler = (tilt, 0, 0)
        d = target - cam.location
    cam_data.dof.use_dof = True          # mild depth of field: focused on the actuator
    cam_data.dof.focus_distance = d.length
    cam_data.dof.aperture_fstop = 8.0

    # light
    world = bpy.data.worlds.new('world')
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes['Background']

    def area(name, loc, power, rgb, size):
        ld = bpy.data.lights.new(name, 'AREA')
        ld.energy = power
        ld.color = rgb
        ld.size = size
        lo = bpy.data.objects.new(name, ld)
        lo.location = loc
        scene.collection.objects.link(lo)
        lo.rotation_euler = (Vector((50 * MM, 0, 60 * MM)) - Vector(loc)).to_track_quat('-Z', 'Y').to_euler()
        return lo

    light = cfg['light']
    if light == 'cold_front':    # ceiling panel in front and above, bluish-white
        area('panel', (60 * MM, -350 * MM, 450 * MM), 7.0, (0.86, 0.93, 1.0), 0.35)
        area('fill', (-250 * MM, -200 * MM, 200 * MM), 1.0, (0.9, 0.95, 1.0), 0.2)
        bg.inputs['Color'].default_value = (0.16, 0.17, 0.19, 1)
        bg.inputs['Strength'].default_value = 0.3
    elif light == 'warm_side':   # a small warm lamp low on the right, nothing else but a dim room
        area('lamp', (330 * MM, -120 * MM, 160 * MM), 1.5, (1.0, 0.62, 0.32), 0.05)
        bg.inputs['Color'].default_value = (0.10, 0.07, 0.05, 1)
        bg.inputs['Strength'].default_value = 0.25
    else:                        # neutral ceiling light
        area('panel', (40 * MM, -120 * MM, 500 * MM), 8.0, (1.0, 0.97, 0.92), 0.4)
        bg.inputs['Color'].default_value = (0.18, 0.18, 0.18, 1)
        bg.inputs['Strength'].default_value = 0.3

    if finger is not None:
        # out of view above the middle marker until frame 6, then down in front of it, following
        # it (so that it stays covered while the actuator bends) in frames 12-21, away by 27
        up = Vector((info[1]['s'] + 12 * MM, -30 * MM, 260 * MM))
        for f in (0, 6, 27, frames):
            finger.location = up
            finger.keyframe_insert('location', frame=f)
        for f in range(12, 22):
            scene.frame_set(f)
            ev = mk.evaluated_get(bpy.context.evaluated_depsgraph_get())
            apex = ev.matrix_world @ ev.data.vertices[info[1]['apex']].co
            finger.location = apex + Vector((4 * MM, -22 * MM, 34 * MM))
            finger.keyframe_insert('location', frame=f)
    return act, mk, cam, info, s_mm


def setup_render(cfg, a):
    scene = bpy.context.scene
    r = scene.render
    r.engine = 'CYCLES'
    r.resolution_x, r.resolution_y = WIDTH, HEIGHT
    r.resolution_percentage = a.scale
    r.fps = FPS
    r.use_motion_blur = True
    r.motion_blur_shutter = cfg.get('shutter', 0.3)
    r.image_settings.file_format = 'PNG'
    r.image_settings.color_mode = 'RGB'
    r.image_settings.color_depth = '8'
    r.threads_mode = 'FIXED'
    r.threads = a.threads
    r.filter_size = 1.5
    c = scene.cycles
    c.device = 'CPU'
    c.samples = a.samples
    c.use_adaptive_sampling = True
    c.adaptive_threshold = 0.03
    c.use_denoising = False          # Debian's Blender has no OpenImageDenoise: samples instead
    c.seed = cfg['seed']
    c.max_bounces = 4
    c.diffuse_bounces = 2
    c.glossy_bounces = 2
    c.transmission_bounces = 2
    c.transparent_max_bounces = 2
    c.caustics_reflective = False
    c.caustics_refractive = False
    c.sample_clamp_indirect = 2.0    # no fireflies from the glossy domes without a denoiser
    c.blur_glossy = 1.0
    scene.view_settings.view_transform = 'Standard'   # a camera's plain sRGB curve, not Filmic
    scene.view_settings.look = 'None'
    scene.view_settings.exposure = -1.0 if cfg['light'] == 'warm_side' else 0.0


def truth(scene, cam, mk, info, frames):
    """Per frame and marker: the apex's projection (pixels) and the visible fraction of the top
    face, by rays from the camera to sample points on it (a point counts when nothing else is
    hit first and it projects inside the frame)."""
    rows, bbox0 = [], []
    for f in range(frames):
        scene.frame_set(f)
        dg = bpy.context.evaluated_depsgraph_get()
        ev = mk.evaluated_get(dg)
        me = ev.to_mesh()
        mw = ev.matrix_world
        eye = cam.matrix_world.translation
        for k, d in enumerate(info):
            def px(p):
                v = world_to_camera_view(scene, cam, p)
                # camera view: (0,0) bottom-left corner, (1,1) top-right; pixel centres at whole numbers
                return v.x * WIDTH - 0.5, (1 - v.y) * HEIGHT - 0.5, v.z
            apex = mw @ me.vertices[d['apex']].co
            x, y, _ = px(apex)
            seen = 0
            for i in d['top']:
                p = mw @ me.vertices[i].co
                q = px(p)
                inside = 0 <= q[0] <= WIDTH - 1 and 0 <= q[1] <= HEIGHT - 1 and q[2] > 0
                dirn = p - eye
                dist = dirn.length
                hit, loc, _, _, obj, _ = scene.ray_cast(dg, eye, dirn.normalized(), distance=dist + 1e-3)
                # the ray may meet the faceted dome a hair before the vertex itself
                clear = (not hit) or (loc - p).length < 1.0 * MM
                seen += inside and clear
            vis = seen / len(d['top'])
            rows.append(dict(frame=f, marker=k, x=x, y=y, visibility=vis))
            if f == 0:
                pts = [px(mw @ me.vertices[i].co) for i in d['rim']]
                xs, ys = [p[0] for p in pts], [p[1] for p in pts]
                bbox0.append([min(xs), min(ys), max(xs), max(ys)])
        ev.to_mesh_clear()
    return rows, bbox0


def moving_box(scene, cam, objects, frames, margin=36):
    """The pixel box (x0, y0, x1, y1) that holds every moving object in every frame, widened by a
    margin for their shadows, motion blur and depth of field."""
    xs, ys = [], []
    for f in range(frames):
        scene.frame_set(f)
        dg = bpy.context.evaluated_depsgraph_get()
        for o in objects:
            ev = o.evaluated_get(dg)
            me = ev.to_mesh()
            mw = ev.matrix_world
            for i in range(0, len(me.vertices), 3):
                p = world_to_camera_view(scene, cam, mw @ me.vertices[i].co)
                xs.append(p.x * WIDTH)
                ys.append((1 - p.y) * HEIGHT)
            ev.to_mesh_clear()
    return [max(0, int(min(xs)) - margin), max(0, int(min(ys)) - margin),
            min(WIDTH, int(max(xs)) + margin), min(HEIGHT, int(max(ys)) + margin)]


def main():
    a = parse()
    cfg = SCENES[a.scene]
    global WIDTH, HEIGHT
    WIDTH, HEIGHT = cfg.get('size', (WIDTH, HEIGHT))
    act, mk, cam, info, s_mm = build(cfg)
    setup_render(cfg, a)
    scene = bpy.context.scene
    frames = a.frames or cfg['frames']
    scene.frame_start, scene.frame_end = 0, frames - 1
    os.makedirs(os.path.join(a.out, 'frames'), exist_ok=True)
    rows, bbox0 = truth(scene, cam, mk, info, frames)
    crop = moving_box(scene, cam, [act, mk] + [o for o in scene.objects if o.name == 'finger'], frames)
    meta = dict(
        scenario=a.scene, what=cfg['what'], seed=cfg['seed'], width=WIDTH, height=HEIGHT, fps=FPS,
        frames=frames, renderer=f'Blender {bpy.app.version_string} Cycles (CPU), scripts/pbr/scene.py',
        samples=a.samples, adaptive_threshold=scene.cycles.adaptive_threshold, denoising=False,
        motion_blur_shutter_frames=scene.render.motion_blur_shutter, hfov_deg=HFOV,
        camera_distance_mm=round(cam.data.dof.focus_distance / MM, 1),
        fstop_36mm_equiv=cam.data.dof.aperture_fstop, layout=cfg['layout'], light=cfg['light'],
        codec=cfg['codec'], sensor_noise_sigma_dn=cfg['noise'], render_crop=crop,
        bend_deg=[round(bend_angle(cfg, f), 3) for f in range(frames)],
        pixel_convention='pixel (row i, column j) has its centre at x = j, y = i; x right, y down',
        truth='projection of the apex (centre of the top face) of each domed marker; visibility = '
              'fraction of sample points on its top face (within 0.65 of its radius) that the camera '
              'sees inside the frame; visible = visibility >= 0.5; angle at each inner marker from '
              'the projected centres of its neighbours',
        markers=[dict(index=k, colour=d['colour'], s_mm=s_mm[k], diameter_mm=2 * DOME_R / MM,
                      length_mm=2 * DOME_R * cfg.get('aspect', 1.0) / MM,
                      nominal_rgb_linear=list(marker_rgb(cfg, d['colour'])),
                      bbox_frame0=[round(v, 2) for v in bbox0[k]])
                 for k, d in enumerate(info)],
        rows=rows)
    with open(os.path.join(a.out, 'truth.json'), 'w') as f:
        json.dump(meta, f, indent=1)
    # Frame 0 is rendered whole; it is also the plate for the others, of which only the part
    # where something moves (plus a margin for shadows and blur) is rendered: the bench and the
    # wall do not change, and the same seed gives the same sampling noise there, so the pasted
    # part has no seam. post.py pastes each part onto the plate.
    t, cpu = time.time(), time.process_time()
    if a.look is not None:
        scene.frame_set(a.look)
        scene.render.filepath = os.path.join(a.out, 'look.png')
        bpy.ops.render.render(write_still=True)
        return
    for f in range(frames):
        scene.frame_set(f)
        r = scene.render
        r.use_border = f > 0
        r.use_crop_to_border = False
        x0, y0, x1, y1 = crop
        r.border_min_x, r.border_max_x = x0 / WIDTH, x1 / WIDTH
        r.border_min_y, r.border_max_y = 1 - y1 / HEIGHT, 1 - y0 / HEIGHT
        r.filepath = os.path.join(a.out, 'frames', f'{f:04d}.png')
        bpy.ops.render.render(write_still=True)
    print(f'PBR_TIMING scene={a.scene} frames={frames} seconds={time.time() - t:.1f} '
          f'cpu_seconds={time.process_time() - cpu:.1f}')


main()
