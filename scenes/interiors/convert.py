#!/usr/bin/env python3
"""Converts Bitterli's interiors (Mitsuba 0.6 XML) into scenes that trilux and
Mitsuba 3 both load: scenes/interiors/<name>/.

Usage:
    python3 scenes/interiors/convert.py DPPM_SCENES [NAME ...] [--out DIR]

DPPM_SCENES is the path of a checkout of https://github.com/hchoi405/dppm-scenes
(Benedikt Bitterli's rendering resources, https://benedikt-bitterli.me/resources/,
as Mitsuba 0.6 files); each scene is read from DPPM_SCENES/scenes/<NAME>/scene.xml
(never the *_rand_scene*.xml variants). NAME defaults to every scene in SCENES
below. DIR defaults to the folder of this script. Needs Python 3.11, numpy and
Pillow (to downscale large textures).

For each scene it writes
    <name>/scene.xml         Mitsuba 3 XML (version 3.0.0, Mitsuba 3's names)
    <name>/meshes/*.ply      binary little-endian PLY: positions, normals when the
                             source mesh has them and uses them, uvs when a
                             texture needs them
    <name>/textures/*        the textures trilux reads (PNG, JPEG), at most
                             MAX_TEXTURE pixels on the longer side
    <name>/LICENSE.txt       the source folder's licence, when it has one
    <name>/SUBSTITUTIONS.md  every change of meaning, per material, shape and
                             emitter: what was there, what it became, why

What trilux reads (README "Scene format"): diffuse, roughconductor (isotropic
GGX or Beckmann, alpha > 0), plastic, roughplastic, blendbsdf, twosided, bitmap textures, area
emitters on shapes; obj/ply/rectangle/cube/disk/sphere/cylinder shapes. The
rules for everything else (the nearest supported equivalent, or removal):

    plastic, roughplastic
                        -> kept (Mitsuba 3's names: diffuse_reflectance,
                           specular_reflectance, int_ior, ext_ior, nonlinear;
                           roughplastic's distribution and alpha as for
                           roughconductor below)
    phong, ward, roughdiffuse
                        -> diffuse with the diffuse reflectance (the specular
                           lobe is dropped)
    conductor           -> roughconductor, GGX, alpha = MIN_ALPHA (the smallest
                           roughness trilux's glTF reader maps to; a mirror
                           cannot be resolved by an element-based solve), same
                           eta/k/specular reflectance
    dielectric, thindielectric, roughdielectric
                        -> shape removed (glass); when its specular
                           transmittance is 0 (an opaque glossy black: marble),
                           roughconductor GGX alpha MIN_ALPHA, material none,
                           specular reflectance 0.04 (Fresnel at normal
                           incidence for IOR 1.5)
    mask                -> its nested BSDF, opaque (trilux has no cut-outs)
    bumpmap             -> its nested BSDF (trilux has no shading-normal maps)
    reflectance > 1     -> clamped to 1 (trilux refuses them)
    sunsky, sky, envmap -> a box just around the scene emitting inward with a
                           constant radiance (the sky's mean over the upper
                           hemisphere, the sun dropped; the map's mean over
                           all directions)
    point, spot, directional -> removed
    serialized meshes   -> PLY (Mitsuba's documented format, parsed here)
    maxSmoothAngle      -> face normals (Mitsuba 3 has no crease angle)
    zero-area triangles -> dropped; shapes of zero total area -> removed
    a mesh or texture file missing from the checkout, or in LEFT_OUT (absent
                        from the snapshot the committed copies were made from)
                        -> the shape removed / the texture replaced by a
                           constant 0.5, listed
    integrator          -> path, max_depth as the source's when >= 64, else -1
                           (trilux's solve has no depth limit)
    film                -> at most FILM_MAX pixels on the longer side
"""
import argparse
import math
import os
import re
import shutil
import struct
import sys
import xml.etree.ElementTree as ET
import zlib

import numpy as np

# The scenes converted by default: those whose source folder states a
# licence. "sponza" and "dining-room" convert too when named, for local
# use; their source folders carry no licence, so no copy is committed.
SCENES = ["staircase", "living-room-2", "classroom", "bathroom", "living-room"]
# Files absent from the snapshot of dppm-scenes (commit 8fdb2dc) the
# committed copies were made from. They are left out whatever the checkout
# holds, so that every checkout gives the same files.
LEFT_OUT = {
    "living-room-2": {"models/Mesh130.obj"},
    "bathroom": {"models/Mesh206.obj", "models/Mesh263.obj", "models/Mesh381.obj", "textures/rug.png"},
}
ABSENT = "absent from the snapshot the committed copies were made from (dppm-scenes 8fdb2dc); left out from every checkout so that all give the same files"
FILM_MAX = 256
MAX_TEXTURE = 1024
MIN_ALPHA = 0.01
# Mean sky radiance (RGB) over the upper hemisphere, sun excluded, for
# sky_scale 1, from Mitsuba 3.9.1's `sunsky` (Hosek-Wilkie) at the scenes'
# turbidity and sun direction, with +y up (to_world = rotate x by -90 deg):
# 20 000 uniformly random directions, scalar_rgb. Keyed by (turbidity, sun
# direction rounded to 3 decimals); a sky not in this table is refused.
SKY_MEAN = {
    (3.0, (-0.866, 0.417, -0.277)): (0.07164, 0.09883, 0.12715),
    (3.0, (0.887, 0.289, 0.36)): (0.06813, 0.08758, 0.10120),
}


# Mean radiance (RGB) of an environment map over all directions (texels
# weighted by the solid angle they cover, sin(theta)), read with Mitsuba
# 3.9.1's Bitmap (numpy has no EXR reader). Keyed by the file's name.
ENV_MEAN = {
    "Sky 19.exr": (11.42488, 7.83410, 5.12506),
}


class Notes:
    """The substitutions of one scene, grouped, each listed once."""

    def __init__(self):
        self.items = {}

    def add(self, group, what, became, why):
        key = (group, what, became, why)
        self.items[key] = self.items.get(key, 0) + 1

    def markdown(self, name, lit):
        out = [f"# {name}: substitutions made by convert.py", "",
               f"Source: dppm-scenes `scenes/{name}/scene.xml` (Mitsuba 0.6). Lit by: {lit}.",
               "Each row is one change of meaning; `count` is how many times it was made.", ""]
        groups = {}
        for (g, what, became, why), n in self.items.items():
            groups.setdefault(g, []).append((what, became, why, n))
        for g in ["scene", "material", "shape", "emitter", "texture", "sensor"]:
            if g not in groups:
                continue
            out += [f"## {g}", "", "| was | became | why | count |", "|---|---|---|---|"]
            for what, became, why, n in groups[g]:
                out.append(f"| {what} | {became} | {why} | {n} |")
            out.append("")
        return "\n".join(out)


# ---------------------------------------------------------------- XML input

def substitute_defaults(root):
    defaults = {d.get("name"): d.get("value") for d in root.iter("default")}

    def sub(v):
        return re.sub(r"\$(\w+)", lambda m: defaults.get(m.group(1), m.group(0)), v)

    for e in root.iter():
        for k, v in list(e.attrib.items()):
            if "$" in v:
                e.set(k, sub(v))


def prop(e, name):
    """The child element (any tag) with the given name attribute."""
    for c in e:
        if c.get("name") == name:
            return c
    return None


def fval(e, name, default=None):
    c = prop(e, name)
    return float(c.get("value")) if c is not None else default


def sval(e, name, default=None):
    c = prop(e, name)
    return c.get("value") if c is not None else default


def bval(e, name, default=False):
    c = prop(e, name)
    return c.get("value").strip().lower() == "true" if c is not None else default


def numbers(s):
    return [float(x) for x in re.split(r"[,\s]+", s.strip()) if x]


def srgb_to_linear(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def color_of(c):
    """A colour element -> list of 3 linear values, or None (spectrum pairs)."""
    if c.tag == "rgb":
        v = numbers(c.get("value"))
        return v * 3 if len(v) == 1 else v
    if c.tag == "srgb":
        v = numbers(c.get("value"))
        v = v * 3 if len(v) == 1 else v
        return [srgb_to_linear(x) for x in v]
    if c.tag in ("spectrum", "float"):
        if ":" in c.get("value", ""):
            return None
        return numbers(c.get("value")) * 3
    return None


def transform_matrix(t):
    """A Mitsuba 0.6 <transform> -> 4x4 numpy matrix (each op applied after the previous)."""
    m = np.eye(4)
    for op in t:
        a = op.attrib
        if op.tag == "matrix":
            o = np.array(numbers(a["value"])).reshape(4, 4)
        elif op.tag == "translate":
            o = np.eye(4)
            o[:3, 3] = [float(a.get("x", 0)), float(a.get("y", 0)), float(a.get("z", 0))]
        elif op.tag == "scale":
            if "value" in a:
                s = [float(a["value"])] * 3
            else:
                s = [float(a.get("x", 1)), float(a.get("y", 1)), float(a.get("z", 1))]
            o = np.diag(s + [1.0])
        elif op.tag == "rotate":
            ax = np.array([float(a.get("x", 0)), float(a.get("y", 0)), float(a.get("z", 0))])
            ax /= np.linalg.norm(ax)
            th = math.radians(float(a["angle"]))
            k = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
            o = np.eye(4)
            o[:3, :3] = np.eye(3) + math.sin(th) * k + (1 - math.cos(th)) * k @ k
        elif op.tag in ("lookat", "lookAt"):
            org = np.array(numbers(a["origin"]))
            tgt = np.array(numbers(a["target"]))
            up = np.array(numbers(a.get("up", "0 1 0")))
            d = tgt - org
            d /= np.linalg.norm(d)
            left = np.cross(up, d)
            left /= np.linalg.norm(left)
            nup = np.cross(d, left)
            o = np.eye(4)
            o[:3, 0], o[:3, 1], o[:3, 2], o[:3, 3] = left, nup, d, org
        else:
            raise ValueError(f"unknown transform op <{op.tag}>")
        m = o @ m
    return m


def matrix_xml(m, name="to_world", indent="        "):
    if np.allclose(m, np.eye(4), atol=0.0, rtol=0.0):
        return ""
    vals = " ".join(f"{x:.9g}" for x in m.reshape(-1))
    return f'{indent}<transform name="{name}">\n{indent}    <matrix value="{vals}"/>\n{indent}</transform>\n'


# ---------------------------------------------------------------- materials

class MaterialBuilder:
    """Converts 0.6 BSDFs into Mitsuba 3 XML text trilux reads."""

    def __init__(self, src_dir, out_dir, ids, notes, left_out):
        self.src_dir, self.out_dir, self.ids, self.notes = src_dir, out_dir, ids, notes
        self.left_out = left_out
        self.textures = {}  # source file -> output name or None (missing)

    def resolve(self, e):
        if e.tag == "ref":
            return self.ids[e.get("id")]
        return e

    def color(self, e, name, default, label, clamp=True):
        """(xml text for parameter `name`, uses_texture)."""
        c = prop(e, name)
        if c is None:
            return (f'<float name="{{n}}" value="{default}"/>', False)
        c = self.resolve(c)
        if c.tag == "texture":
            return self.texture(c, label)
        if c.tag == "spectrum" and ":" in c.get("value", ""):
            return (f'<spectrum name="{{n}}" value="{c.get("value")}"/>', False)
        v = color_of(c)
        if v is None:
            raise ValueError(f"cannot read colour <{c.tag}> of {label}")
        if clamp and max(v) > 1.0:
            self.notes.add("material", f"`{label}` reflectance {fmt(v)}", "clamped to 1", "trilux refuses reflectances above 1")
            v = [min(x, 1.0) for x in v]
        return (f'<rgb name="{{n}}" value="{fmt(v)}"/>', False)

    def texture(self, t, label):
        typ = t.get("type")
        if typ != "bitmap":
            self.notes.add("texture", f"`{label}`: texture `{typ}`", "constant 0.5", "trilux reads bitmap textures only")
            return ('<float name="{n}" value="0.5"/>', False)
        fn = sval(t, "filename")
        out = self.copy_texture(fn, label)
        if out is None:
            return ('<float name="{n}" value="0.5"/>', False)
        parts = [f'<string name="filename" value="textures/{out}"/>']
        ft = sval(t, "filterType", "ewa")
        parts.append(f'<string name="filter_type" value="{"nearest" if ft == "nearest" else "bilinear"}"/>')
        if ft not in ("nearest", "bilinear"):
            self.notes.add("texture", f"filterType `{ft}`", "filter_type bilinear", "Mitsuba 3 has no mipmapped filters")
        wm = sval(t, "wrapMode")
        if wm in ("repeat", "mirror", "clamp"):
            parts.append(f'<string name="wrap_mode" value="{wm}"/>')
        gamma = fval(t, "gamma", -1.0)
        if gamma == 1.0:
            parts.append('<boolean name="raw" value="true"/>')
        elif gamma != -1.0:
            self.notes.add("texture", f"`{fn}` gamma {gamma}", "sRGB", "Mitsuba 3 decodes sRGB or raw only")
        us, vs = fval(t, "uscale", 1.0), fval(t, "vscale", 1.0)
        uo, vo = fval(t, "uoffset", 0.0), fval(t, "voffset", 0.0)
        if (us, vs, uo, vo) != (1.0, 1.0, 0.0, 0.0):
            parts.append(
                f'<transform name="to_uv"><scale x="{us}" y="{vs}"/><translate x="{uo}" y="{vo}"/></transform>')
        inner = "".join(parts)
        return ('<texture type="bitmap" name="{n}">' + inner + "</texture>", True)

    def copy_texture(self, fn, label):
        if fn in self.textures:
            return self.textures[fn]
        src = os.path.join(self.src_dir, fn)
        base = os.path.basename(fn)
        if fn in self.left_out or not os.path.isfile(src):
            why = ABSENT if fn in self.left_out else "the file is not in the checkout"
            self.notes.add("texture", f"`{fn}` (of `{label}`)", "constant 0.5", why)
            self.textures[fn] = None
            return None
        from PIL import Image
        os.makedirs(os.path.join(self.out_dir, "textures"), exist_ok=True)
        im = Image.open(src)
        stem, ext = os.path.splitext(base)
        fmt_ok = im.format in ("JPEG", "PNG")
        w, h = im.size
        if max(w, h) > MAX_TEXTURE or not fmt_ok:
            s = min(1.0, MAX_TEXTURE / max(w, h))
            nw, nh = max(1, round(w * s)), max(1, round(h * s))
            if im.mode not in ("RGB", "L"):
                im = im.convert("RGB")
            im2 = im.resize((nw, nh), Image.LANCZOS) if s < 1 else im
            if im.format == "JPEG" or (not fmt_ok and im.format != "PNG"):
                out = stem + ".jpg"
                im2.save(os.path.join(self.out_dir, "textures", out), quality=90)
            else:
                out = stem + ".png"
                im2.save(os.path.join(self.out_dir, "textures", out), optimize=True)
            what = f"{w}x{h} {im.format}"
            self.notes.add("texture", f"`{fn}` {what}", f"`textures/{out}` {nw}x{nh}",
                           "downscaled to keep the repository small" if s < 1 else "trilux reads PNG and JPEG only")
        else:
            out = stem + ext.lower()
            shutil.copyfile(src, os.path.join(self.out_dir, "textures", out))
        self.textures[fn] = out
        return out

    def convert(self, e, label):
        """0.6 BSDF element -> (Mitsuba 3 XML text or None = remove shape, needs_uv)."""
        e = self.resolve(e)
        label = e.get("id", label)
        typ = e.get("type")
        nested = [self.resolve(c) for c in e if c.tag == "bsdf" or (c.tag == "ref" and self.ids.get(c.get("id")) is not None and self.ids[c.get("id")].tag == "bsdf")]
        if typ == "twosided":
            inner, uv = self.convert(nested[0], label)
            if inner is None:
                return None, False
            if inner.startswith('<bsdf type="twosided"'):
                return inner, uv
            return f'<bsdf type="twosided">{inner}</bsdf>', uv
        if typ == "diffuse":
            x, uv = self.color(e, "reflectance", 0.5, label)
            return '<bsdf type="diffuse">' + x.format(n="reflectance") + "</bsdf>", uv
        if typ in ("plastic", "roughplastic"):
            return self.plastic(e, typ, label)
        if typ in ("phong", "ward", "roughdiffuse"):
            pname = "reflectance" if typ == "roughdiffuse" else "diffuseReflectance"
            x, uv = self.color(e, pname, 0.5, label)
            why = {"roughdiffuse": "Mitsuba 3 and trilux have no Oren-Nayar; its Lambertian limit",
                   }.get(typ, "trilux has no coated or Phong/Ward model; its diffuse part kept, the specular lobe dropped")
            self.notes.add("material", f"`{label}`: {typ}", "diffuse, its diffuse reflectance", why)
            return '<bsdf type="diffuse">' + x.format(n="reflectance") + "</bsdf>", uv
        if typ in ("conductor", "roughconductor"):
            return self.conductor(e, typ, label)
        if typ in ("dielectric", "thindielectric", "roughdielectric"):
            st = prop(e, "specularTransmittance")
            if st is not None and color_of(st) is not None and max(color_of(st)) == 0.0:
                self.notes.add("material", f"`{label}`: {typ} with specularTransmittance 0", "roughconductor GGX alpha 0.01, material none, specular_reflectance 0.04",
                               "an opaque glossy black; 0.04 is the Fresnel reflectance at IOR 1.5, the smallest alpha trilux resolves")
                return (f'<bsdf type="roughconductor"><string name="distribution" value="ggx"/><float name="alpha" value="{MIN_ALPHA}"/>'
                        '<string name="material" value="none"/><rgb name="specular_reflectance" value="0.04, 0.04, 0.04"/></bsdf>', False)
            self.notes.add("material", f"`{label}`: {typ}", "its shapes removed", "trilux has no transmission (glass)")
            return None, False
        if typ == "mask":
            inner, uv = self.convert(nested[0], label)
            op = prop(e, "opacity")
            opdesc = "textured" if op is not None and self.resolve(op).tag == "texture" else (fmt(color_of(op)) if op is not None else "0.5")
            self.notes.add("material", f"`{label}`: mask, opacity {opdesc}", "its nested BSDF, opaque", "trilux has no cut-outs or partial opacity")
            return inner, uv
        if typ == "bumpmap":
            inner, uv = self.convert(nested[0], label)
            self.notes.add("material", f"`{label}`: bumpmap", "its nested BSDF", "trilux has no bump maps (shading normals only)")
            return inner, uv
        if typ == "blendbsdf":
            a, ua = self.convert(nested[0], label)
            b, ub = self.convert(nested[1], label)
            if a is None or b is None:
                return (a or b), (ua if a else ub)
            w, uw = self.color(e, "weight", 0.5, label)
            return '<bsdf type="blendbsdf">' + w.format(n="weight") + a + b + "</bsdf>", ua or ub or uw
        self.notes.add("material", f"`{label}`: {typ}", "diffuse 0.5", "no nearer model in trilux")
        return '<bsdf type="diffuse"/>', False

    def roughness(self, e, label):
        """0.6 distribution and alpha(U/V) -> (Mitsuba 3 distribution, isotropic alpha)."""
        dist = sval(e, "distribution", "beckmann")
        au, av = fval(e, "alphaU"), fval(e, "alphaV")
        alpha = fval(e, "alpha", 0.1)
        if au is not None or av is not None:
            au = au if au is not None else 0.1
            av = av if av is not None else 0.1
            alpha = 0.5 * (au + av)
            if au != av:
                self.notes.add("material", f"`{label}`: anisotropic alpha {au}/{av}", f"alpha {alpha}", "trilux refuses anisotropic roughness")
        if dist not in ("ggx", "beckmann"):
            self.notes.add("material", f"`{label}`: distribution {dist}", "ggx", "Mitsuba 3 and trilux have Beckmann and GGX only")
            dist = "ggx"
        if alpha < MIN_ALPHA:
            self.notes.add("material", f"`{label}`: alpha {alpha}", f"alpha {MIN_ALPHA}", "the smallest roughness trilux resolves")
            alpha = MIN_ALPHA
        return dist, alpha

    def plastic(self, e, typ, label):
        """plastic/roughplastic, kept: Mitsuba 0.6 names -> Mitsuba 3 names."""
        parts = []
        if typ == "roughplastic":
            dist, alpha = self.roughness(e, label)
            parts.append(f'<string name="distribution" value="{dist}"/><float name="alpha" value="{alpha:g}"/>')
        for old, new in (("intIOR", "int_ior"), ("extIOR", "ext_ior")):
            p = prop(e, old)
            if p is None:
                continue
            if p.tag == "string":
                parts.append(f'<string name="{new}" value="{p.get("value")}"/>')
            else:
                parts.append(f'<float name="{new}" value="{float(p.get("value")):g}"/>')
        nl = prop(e, "nonlinear")
        if nl is not None and nl.get("value") == "true":
            parts.append('<boolean name="nonlinear" value="true"/>')
        x, uv = self.color(e, "diffuseReflectance", 0.5, label)
        parts.append(x.format(n="diffuse_reflectance"))
        sp = prop(e, "specularReflectance")
        if sp is not None:
            if self.resolve(sp).tag == "texture":
                self.notes.add("material", f"`{label}`: {typ} with a specularReflectance texture", "specular_reflectance 1",
                               "trilux takes a texture on a plastic's diffuse_reflectance only")
            else:
                y, _ = self.color(e, "specularReflectance", 1.0, label)
                parts.append(y.format(n="specular_reflectance"))
        return f'<bsdf type="{typ}">' + "".join(parts) + "</bsdf>", uv

    def conductor(self, e, typ, label):
        parts = []
        if typ == "conductor":
            alpha = MIN_ALPHA
            dist = "ggx"
            self.notes.add("material", f"`{label}`: conductor (smooth)", f"roughconductor GGX alpha {MIN_ALPHA}",
                           "trilux needs alpha > 0; 0.01 is the smallest roughness it maps glTF to (a mirror cannot be resolved by elements)")
        else:
            dist, alpha = self.roughness(e, label)
        parts.append(f'<string name="distribution" value="{dist}"/><float name="alpha" value="{alpha:g}"/>')
        material = sval(e, "material")
        eta, k = prop(e, "eta"), prop(e, "k")
        if eta is not None and k is not None:
            ev, kv = color_of(eta), color_of(k)
            if min(ev + kv) < 0:
                self.notes.add("material", f"`{label}`: eta {fmt(ev)}, k {fmt(kv)}", "negative values set to 0",
                               "trilux refuses a negative eta or k (an RGB fit's artefact)")
                ev, kv = [max(x, 0.0) for x in ev], [max(x, 0.0) for x in kv]
            parts.append(f'<rgb name="eta" value="{fmt(ev)}"/><rgb name="k" value="{fmt(kv)}"/>')
        elif material == "none":
            parts.append('<string name="material" value="none"/>')
        else:
            # Mitsuba 0.6's default material is Cu; none of these scenes
            # names a material (or leaves it to the default) without eta/k.
            raise ValueError(f"{label}: named conductor material {material or 'Cu (the default)'} is not handled")
        ext = fval(e, "extEta", 1.0)
        if ext != 1.0:
            self.notes.add("material", f"`{label}`: extEta {ext}", "1 (air)", "trilux has no exterior IOR")
        if prop(e, "specularReflectance") is not None:
            x, uv = self.color(e, "specularReflectance", 1.0, label)
            parts.append(x.format(n="specular_reflectance"))
        else:
            uv = False
        return '<bsdf type="roughconductor">' + "".join(parts) + "</bsdf>", uv


def fmt(v):
    return ", ".join(f"{x:.6g}" for x in v)


# ---------------------------------------------------------------- meshes

def read_obj(path, want_uv, want_normals):
    """OBJ -> (positions, normals or None, uvs or None, triangles): vertices
    split by (v, vt, vn) as Mitsuba does; polygons as fans; uv v flipped
    (Mitsuba's default flip_tex_coords for OBJ) so that the PLY reads as the
    OBJ did."""
    vs, vts, vns = [], [], []
    key_index = {}
    out_v, tris = [], []
    with open(path, "r", errors="replace") as f:
        for line in f:
            if not line or line[0] not in "vf":
                continue
            p = line.split()
            if not p:
                continue
            t = p[0]
            if t == "v":
                vs.append((float(p[1]), float(p[2]), float(p[3])))
            elif t == "vt":
                vts.append((float(p[1]), float(p[2]) if len(p) > 2 else 0.0))
            elif t == "vn":
                vns.append((float(p[1]), float(p[2]), float(p[3])))
            elif t == "f":
                idx = []
                for c in p[1:]:
                    s = c.split("/")
                    vi = int(s[0])
                    vi = vi - 1 if vi > 0 else len(vs) + vi
                    ti = ni = -1
                    if want_uv and len(s) > 1 and s[1]:
                        ti = int(s[1])
                        ti = ti - 1 if ti > 0 else len(vts) + ti
                    if want_normals and len(s) > 2 and s[2]:
                        ni = int(s[2])
                        ni = ni - 1 if ni > 0 else len(vns) + ni
                    key = (vi, ti, ni)
                    j = key_index.get(key)
                    if j is None:
                        j = len(out_v)
                        key_index[key] = j
                        out_v.append(key)
                    idx.append(j)
                for i in range(1, len(idx) - 1):
                    tris.append((idx[0], idx[i], idx[i + 1]))
    keys = np.array(out_v, dtype=np.int64).reshape(-1, 3)
    P = np.array(vs, dtype=np.float64)[keys[:, 0]]
    N = UV = None
    if want_normals and vns and (keys[:, 2] >= 0).all():
        N = np.array(vns, dtype=np.float64)[keys[:, 2]]
    if want_uv and vts and (keys[:, 1] >= 0).all():
        UV = np.array(vts, dtype=np.float64)[keys[:, 1]]
        UV[:, 1] = 1.0 - UV[:, 1]
    return P, N, UV, np.array(tris, dtype=np.int64).reshape(-1, 3)


def read_serialized(path, index):
    """One shape of a Mitsuba `serialized` file -> (positions, normals, uvs,
    triangles, face_normals flag). Layout (Mitsuba's documentation): per
    shape, uint16 0x041C, uint16 version (3 or 4), then a zlib stream:
    uint32 flags, [v4: a NUL-terminated name], uint64 vertex count, uint64
    triangle count, positions, [normals], [uvs], [colours], indices; the file
    ends with the shapes' offsets (uint64 in v4, uint32 in v3) and a uint32
    shape count."""
    with open(path, "rb") as f:
        data = f.read()
    count = struct.unpack_from("<I", data, len(data) - 4)[0]
    fmt_id, version = struct.unpack_from("<HH", data, 0)
    if fmt_id != 0x041C:
        raise ValueError(f"{path}: not a Mitsuba serialized file")
    if version >= 4:
        offs = struct.unpack_from(f"<{count}Q", data, len(data) - 4 - 8 * count)
    else:
        offs = struct.unpack_from(f"<{count}I", data, len(data) - 4 - 4 * count)
    off = offs[index]
    fid, ver = struct.unpack_from("<HH", data, off)
    raw = zlib.decompressobj().decompress(data[off + 4:])
    pos = 0
    flags = struct.unpack_from("<I", raw, pos)[0]
    pos += 4
    if ver >= 4:
        end = raw.index(b"\0", pos)
        pos = end + 1
    nv, nt = struct.unpack_from("<QQ", raw, pos)
    pos += 16
    dt = np.float64 if flags & 0x2000 else np.float32

    def take(n, dtype):
        nonlocal pos
        a = np.frombuffer(raw, dtype=dtype, count=n, offset=pos)
        pos += n * np.dtype(dtype).itemsize
        return a

    P = take(3 * nv, dt).reshape(-1, 3).astype(np.float64)
    N = take(3 * nv, dt).reshape(-1, 3).astype(np.float64) if flags & 0x0001 else None
    UV = take(2 * nv, dt).reshape(-1, 2).astype(np.float64) if flags & 0x0002 else None
    if flags & 0x0008:
        take(3 * nv, dt)
    it = np.uint64 if nv > 0xFFFFFFFF else np.uint32
    T = take(3 * nt, it).reshape(-1, 3).astype(np.int64)
    return P, N, UV, T, bool(flags & 0x0010)


def write_ply(path, P, N, UV, T):
    props = ["x", "y", "z"] + (["nx", "ny", "nz"] if N is not None else []) + (["u", "v"] if UV is not None else [])
    head = ["ply", "format binary_little_endian 1.0", f"element vertex {len(P)}"]
    head += [f"property float {p}" for p in props]
    head += [f"element face {len(T)}", "property list uchar int vertex_indices", "end_header"]
    cols = [P] + ([N] if N is not None else []) + ([UV] if UV is not None else [])
    V = np.hstack(cols).astype("<f4")
    F = np.zeros(len(T), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    F["n"] = 3
    F["i"] = T
    with open(path, "wb") as f:
        f.write(("\n".join(head) + "\n").encode("ascii"))
        f.write(V.tobytes())
        f.write(F.tobytes())


def clean_mesh(P, N, UV, T):
    """Drops triangles of zero area (in object space: a linear map keeps them
    zero) and the vertices no triangle uses."""
    a = np.linalg.norm(np.cross(P[T[:, 1]] - P[T[:, 0]], P[T[:, 2]] - P[T[:, 0]]), axis=1)
    keep = a > 0
    dropped = int((~keep).sum())
    T = T[keep]
    used = np.unique(T)
    remap = -np.ones(len(P), dtype=np.int64)
    remap[used] = np.arange(len(used))
    P = P[used]
    N = N[used] if N is not None else None
    UV = UV[used] if UV is not None else None
    return P, N, UV, remap[T], dropped


def world_area(P, T, m):
    Q = P @ m[:3, :3].T
    return 0.5 * np.linalg.norm(np.cross(Q[T[:, 1]] - Q[T[:, 0]], Q[T[:, 2]] - Q[T[:, 0]]), axis=1).sum()


# ---------------------------------------------------------------- scene

def convert_scene(src_root, name, out_root):
    src_dir = os.path.join(src_root, "scenes", name)
    out_dir = os.path.join(out_root, name)
    if os.path.isdir(out_dir):
        shutil.rmtree(out_dir)
    os.makedirs(os.path.join(out_dir, "meshes"))
    notes = Notes()
    root = ET.parse(os.path.join(src_dir, "scene.xml")).getroot()
    substitute_defaults(root)
    ids = {e.get("id"): e for e in root.iter() if e.get("id") and e.tag in ("bsdf", "texture")}
    mats = MaterialBuilder(src_dir, out_dir, ids, notes, LEFT_OUT.get(name, set()))

    out = ['<?xml version="1.0" encoding="utf-8"?>',
           f"<!-- {name}: converted from hchoi405/dppm-scenes scenes/{name}/scene.xml (Mitsuba 0.6)",
           "     by scenes/interiors/convert.py; changes of meaning in SUBSTITUTIONS.md. -->",
           '<scene version="3.0.0">']

    # integrator
    integ = root.find("integrator")
    md = int(fval(integ, "maxDepth", -1)) if integ is not None else -1
    if md != -1 and md < 64:
        notes.add("scene", f"integrator {integ.get('type')} maxDepth {md}", "path, max_depth -1",
                  "trilux's solve has no depth limit; its reference must not have one either")
        md = -1
    elif integ is not None and integ.get("type") != "path":
        notes.add("scene", f"integrator {integ.get('type')} maxDepth {md}", f"path, max_depth {md}",
                  "the reference is a path tracer (trilux reads max_depth only)")
    out.append(f'    <integrator type="path">\n        <integer name="max_depth" value="{md}"/>\n    </integrator>')

    sensor_xml(root.find("sensor"), out, notes)

    bsdf_cache = {}  # id(element) -> (xml, uv, id)
    top_bsdfs = []
    shapes_out = []
    mesh_cache = {}  # (file, index, uv, normals, face) -> (ply name, triangles, P, T)
    bbox = [np.full(3, np.inf), np.full(3, -np.inf)]
    stats = {"triangles": 0, "shapes": 0, "dropped_tris": 0, "emitters": 0, "sky": ""}

    for sh in root.findall("shape"):
        shape_out = convert_shape(sh, src_dir, out_dir, mats, notes, bsdf_cache, top_bsdfs, mesh_cache, bbox, stats)
        if shape_out:
            shapes_out.append(shape_out)

    # emitters outside shapes
    for em in root.findall("emitter"):
        typ = em.get("type")
        if typ in ("sunsky", "sky", "envmap"):
            shapes_out.append(sky_box(em, bbox, notes))
            stats["sky"] = typ + (" (without the sun)" if typ == "sunsky" else "")
        else:
            notes.add("emitter", f"{typ}", "removed", "trilux reads area emitters on shapes only")

    for bid, x in top_bsdfs:
        out.append(indent_bsdf(bid, x))
    out += shapes_out
    out.append("</scene>\n")
    with open(os.path.join(out_dir, "scene.xml"), "w") as f:
        f.write("\n".join(out))
    lic = os.path.join(src_dir, "LICENSE.txt")
    if os.path.isfile(lic):
        shutil.copyfile(lic, os.path.join(out_dir, "LICENSE.txt"))
    if stats["dropped_tris"]:
        notes.add("shape", f"{stats['dropped_tris']} triangles of zero area (over all meshes)", "dropped", "they are never hit; trilux would make elements of them")
    with open(os.path.join(out_dir, "SUBSTITUTIONS.md"), "w") as f:
        lit = f"{stats['emitters']} area emitter(s) of the source" if stats["emitters"] else "no emitter of the source"
        if stats["sky"]:
            lit += " and the constant sky box standing for its " + stats["sky"]
        f.write(notes.markdown(name, lit))
    print(f"{name}: {stats['shapes']} shapes, {stats['triangles']} triangles")
    return stats


def indent_bsdf(bid, x):
    assert x.startswith("<bsdf ")
    return f'    <bsdf id="{bid}" ' + x[len("<bsdf "):]


def sensor_xml(s, out, notes):
    fov = fval(s, "fov")
    axis = sval(s, "fovAxis", "x")
    t = transform_matrix(prop(s, "toWorld"))
    R = t[:3, :3]
    if not np.allclose(R.T @ R, np.eye(3), atol=1e-4) or np.linalg.det(R) < 0:
        raise ValueError("sensor to_world is not a rotation")
    org, d, up = t[:3, 3], R[:, 2], R[:, 1]
    tgt = org + d
    film = s.find("film")
    w, h = int(fval(film, "width", 768)), int(fval(film, "height", 576))
    sc = FILM_MAX / max(w, h)
    nw, nh = max(1, round(w * sc)), max(1, round(h * sc))
    notes.add("sensor", f"film {w}x{h}", f"film {nw}x{nh}", f"at most {FILM_MAX} pixels on the longer side (the same field of view)")
    rf = film.find("rfilter")
    rft = rf.get("type") if rf is not None else "gaussian"
    spp = int(fval(s.find("sampler"), "sampleCount", 4))
    lines = ['    <sensor type="perspective">']
    if fov is not None:
        lines.append(f'        <float name="fov" value="{fov:g}"/>')
    lines.append(f'        <string name="fov_axis" value="{axis}"/>')
    nc, fc = fval(s, "nearClip"), fval(s, "farClip")
    if nc is not None:
        lines.append(f'        <float name="near_clip" value="{nc:g}"/>')
    if fc is not None:
        lines.append(f'        <float name="far_clip" value="{fc:g}"/>')
    if fval(s, "focusDistance") is not None:
        pass  # a pinhole camera: focusDistance has no effect
    lines.append('        <transform name="to_world">')
    lines.append(f'            <lookat origin="{fmt(org)}" target="{fmt(tgt)}" up="{fmt(up)}"/>')
    lines.append("        </transform>")
    lines.append(f'        <sampler type="independent">\n            <integer name="sample_count" value="{spp}"/>\n        </sampler>')
    lines.append('        <film type="hdrfilm">')
    lines.append(f'            <integer name="width" value="{nw}"/>\n            <integer name="height" value="{nh}"/>')
    lines.append(f'            <rfilter type="{rft}"/>')
    lines.append('            <string name="pixel_format" value="rgb"/>')
    lines.append("        </film>")
    lines.append("    </sensor>")
    out.append("\n".join(lines))


def shape_bsdf(sh, mats, bsdf_cache, top_bsdfs):
    """(reference xml or inline xml, needs_uv) or (None, _) to remove."""
    b = None
    for c in sh:
        if c.tag == "bsdf" or (c.tag == "ref" and c.get("id") in mats.ids and mats.ids[c.get("id")].tag == "bsdf"):
            b = mats.resolve(c)
    if b is None:
        return '', False
    key = id(b)
    if key not in bsdf_cache:
        x, uv = mats.convert(b, b.get("id", "(unnamed)"))
        bid = None
        if x is not None and b.get("id"):
            bid = re.sub(r"[^A-Za-z0-9_.-]", "_", b.get("id"))
            top_bsdfs.append((bid, x))
        bsdf_cache[key] = (x, uv, bid)
    x, uv, bid = bsdf_cache[key]
    if x is None:
        return None, False
    return (f'        <ref id="{bid}"/>\n' if bid else f"        {x}\n"), uv


def convert_shape(sh, src_dir, out_dir, mats, notes, bsdf_cache, top_bsdfs, mesh_cache, bbox, stats):
    typ = sh.get("type")
    tw = prop(sh, "toWorld")
    m = transform_matrix(tw) if tw is not None else np.eye(4)
    bx, uv = shape_bsdf(sh, mats, bsdf_cache, top_bsdfs)
    em = sh.find("emitter")
    src_name = sval(sh, "filename", typ)
    if bx is None:
        if em is not None:
            raise ValueError("an emitting shape with a removed material")
        b = [mats.resolve(c) for c in sh if c.tag in ("bsdf", "ref")][-1]
        notes.add("shape", f"a shape of material `{b.get('id', '(unnamed)')}` ({src_name})", "removed", "its material is glass")
        return None
    em_xml = ""
    if em is not None:
        if em.get("type") != "area":
            notes.add("emitter", f"{em.get('type')} on a shape", "removed", "trilux reads area emitters only")
        else:
            r = prop(em, "radiance")
            if r is None:
                em_xml = '        <emitter type="area"/>\n'
            elif r.tag == "spectrum":
                em_xml = f'        <emitter type="area"><spectrum name="radiance" value="{r.get("value")}"/></emitter>\n'
            else:
                em_xml = f'        <emitter type="area"><rgb name="radiance" value="{fmt(color_of(r))}"/></emitter>\n'
            stats["emitters"] += 1
    flip = bval(sh, "flipNormals")
    extra = '        <boolean name="flip_normals" value="true"/>\n' if flip else ""
    if typ in ("obj", "serialized", "ply"):
        fn = sval(sh, "filename")
        idx = int(fval(sh, "shapeIndex", 0))
        face = bval(sh, "faceNormals")
        msa = fval(sh, "maxSmoothAngle")
        if msa is not None:
            notes.add("shape", f"`{fn}`#{idx}: maxSmoothAngle {msa:g}", "face normals", "Mitsuba 3 has no crease angle")
            face = True
        path = os.path.join(src_dir, fn)
        if fn in mats.left_out or not os.path.isfile(path):
            notes.add("shape", f"`{fn}`", "removed", ABSENT if fn in mats.left_out else "the file is not in the checkout")
            return None
        key = (fn, idx, uv, face)
        if key not in mesh_cache:
            if typ == "obj":
                P, N, UV, T = read_obj(path, uv, not face)
            elif typ == "serialized":
                P, N, UV, T, fflag = read_serialized(path, idx)
                face = face or fflag
                if face:
                    N = None
                if not uv:
                    UV = None
            else:
                raise ValueError("ply input not handled")
            if uv and UV is None:
                notes.add("shape", f"`{fn}`: textured without uvs", "uv (0, 0) everywhere", "the mesh has no texture coordinates")
                UV = np.zeros((len(P), 2))
            P, N, UV, T, dropped = clean_mesh(P, N, UV, T)
            stats["dropped_tris"] += dropped
            stem = os.path.splitext(os.path.basename(fn))[0] + (f"_{idx}" if typ == "serialized" else "")
            base = stem
            k = 1
            while any(v[0] == base + ".ply" for v in mesh_cache.values()):
                base = f"{stem}_{k}"
                k += 1
            ply = base + ".ply"
            if len(T):
                write_ply(os.path.join(out_dir, "meshes", ply), P, N, UV, T)
            mesh_cache[key] = (ply, P, T, face)
        ply, P, T, face = mesh_cache[key]
        if len(T) == 0 or world_area(P, T, m) <= 0.0:
            notes.add("shape", f"`{fn}` (zero area)", "removed", "never hit; trilux refuses shapes of zero area")
            return None
        Q = P @ m[:3, :3].T + m[:3, 3]
        bbox[0] = np.minimum(bbox[0], Q.min(axis=0))
        bbox[1] = np.maximum(bbox[1], Q.max(axis=0))
        stats["triangles"] += len(T)
        stats["shapes"] += 1
        body = f'        <string name="filename" value="meshes/{ply}"/>\n'
        if face:
            body += '        <boolean name="face_normals" value="true"/>\n'
        return f'    <shape type="ply">\n{body}{matrix_xml(m)}{extra}{bx}{em_xml}    </shape>'
    if typ in ("rectangle", "cube", "disk", "sphere", "cylinder"):
        L = m[:3, :3]
        if typ == "rectangle":
            area = 4 * np.linalg.norm(np.cross(L[:, 0], L[:, 1]))
        elif typ == "disk":
            area = math.pi * np.linalg.norm(np.cross(L[:, 0], L[:, 1]))
        else:
            area = abs(np.linalg.det(L)) if typ != "sphere" else 1.0
        if area <= 0:
            notes.add("shape", f"{typ} (zero area)", "removed", "trilux refuses shapes of zero area")
            return None
        body = ""
        if typ == "sphere":
            c = prop(sh, "center")
            r = fval(sh, "radius", 1.0)
            if c is not None:
                cx = [float(c.get(a, 0)) for a in "xyz"] if c.get("x") is not None else numbers(c.get("value"))
                body += f'        <point name="center" value="{fmt(cx)}"/>\n'
                Cw = m[:3, :3] @ np.array(cx) + m[:3, 3]
            else:
                Cw = m[:3, 3]
            body += f'        <float name="radius" value="{r:g}"/>\n'
            s = np.linalg.norm(m[:3, 0]) * r
            bbox[0] = np.minimum(bbox[0], Cw - s)
            bbox[1] = np.maximum(bbox[1], Cw + s)
        elif typ == "cylinder":
            raise ValueError("cylinder not handled")
        else:
            corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in ((-1, 1) if typ == "cube" else (0,))])
            Q = corners @ L.T + m[:3, 3]
            bbox[0] = np.minimum(bbox[0], Q.min(axis=0))
            bbox[1] = np.maximum(bbox[1], Q.max(axis=0))
        stats["shapes"] += 1
        return f'    <shape type="{typ}">\n{body}{matrix_xml(m)}{extra}{bx}{em_xml}    </shape>'
    notes.add("shape", f"{typ}", "removed", "not a shape trilux reads")
    return None


def sky_box(em, bbox, notes):
    """A constant sky: a box just around the scene's bounds emitting inward.
    Any closed emitter of constant radiance around the scene looks the same
    from inside; a box keeps the scene's bounding box (trilux's MinArea is a
    fraction of its diagonal) almost as it was, where a sphere or a distant
    sun would enlarge it."""
    typ = em.get("type")
    c = 0.5 * (bbox[0] + bbox[1])
    half = 0.5 * (bbox[1] - bbox[0])
    half = half * 1.02 + 1e-3 * float(np.linalg.norm(bbox[1] - bbox[0]))
    if typ in ("sunsky", "sky"):
        t = fval(em, "turbidity", 3.0)
        d = prop(em, "sunDirection")
        dv = tuple(round(float(d.get(a)), 3) for a in "xyz")
        mean = SKY_MEAN.get((t, dv))
        if mean is None:
            raise ValueError(f"no sky mean for turbidity {t}, sun {dv}: add it to SKY_MEAN")
        s = fval(em, "skyScale", 1.0)
        L = [x * s for x in mean]
        notes.add("emitter", f"{typ} (turbidity {t:g}, sunDirection {fmt(dv)}, skyScale {s:g}, sunScale {fval(em, 'sunScale', 1.0):g}, sunRadiusScale {fval(em, 'sunRadiusScale', 1.0):g})",
                  f"a cube around the scene (centre {fmt(c)}, half-extents {fmt(half)}, 2 % beyond its bounds) emitting inward a constant radiance {fmt(L)}, black; no sun",
                  "trilux reads area emitters only. The sky's mean radiance over the upper hemisphere (Mitsuba 3.9.1's sunsky at the same turbidity and sun direction, sun excluded, times skyScale) stands for the sky, from every direction (the ground below the horizon as bright as the sky). The sun is dropped: a distant disk would enlarge the scene's bounds (and trilux's MinArea with them) and a near one would shift its patches. The room is lit by that uniform sky through its openings only, without sunlit patches")
    elif typ == "envmap":
        fn = os.path.basename(sval(em, "filename"))
        if fn not in ENV_MEAN:
            raise ValueError(f"no mean radiance for the environment map {fn}: add it to ENV_MEAN")
        s = fval(em, "scale", 1.0)
        L = [x * s for x in ENV_MEAN[fn]]
        notes.add("emitter", f"envmap `{fn}` (scale {s:g})",
                  f"a cube around the scene (centre {fmt(c)}, half-extents {fmt(half)}, 2 % beyond its bounds) emitting inward a constant radiance {fmt(L)}, black",
                  "trilux reads area emitters only. The map's mean radiance over all directions (its total power kept) stands for it, from every direction; the room is lit by that uniform sky through its openings")
    else:
        raise ValueError(f"{typ}: no constant radiance known")
    m = np.eye(4)
    m[:3, :3] = np.diag(half)
    m[:3, 3] = c
    return ('    <shape type="cube">\n' + matrix_xml(m) +
            '        <boolean name="flip_normals" value="true"/>\n'
            '        <bsdf type="diffuse"><rgb name="reflectance" value="0, 0, 0"/></bsdf>\n'
            f'        <emitter type="area"><rgb name="radiance" value="{fmt(L)}"/></emitter>\n    </shape>')


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("checkout", help="path of a checkout of https://github.com/hchoi405/dppm-scenes")
    ap.add_argument("names", nargs="*", default=SCENES)
    ap.add_argument("--out", default=os.path.dirname(os.path.abspath(__file__)))
    a = ap.parse_args()
    for n in a.names:
        convert_scene(a.checkout, n, a.out)


if __name__ == "__main__":
    sys.exit(main())
