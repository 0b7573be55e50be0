#!/usr/bin/env python3
"""Upgrades a Mitsuba 0.6 scene file to Mitsuba 3 XML, printing every change.

Usage:
    python3 scripts/mitsuba06_to_3.py SCENE_0.6.xml [-o SCENE_3.xml]

The result (stdout without -o) is version 3.0.0 XML that Mitsuba 3 loads as
it is, and trilux too when it uses only what trilux reads (README, "Scene
format"). Each change is one line on stderr, `upgrade: ...`; a plugin with no
Mitsuba 3 equivalent is left as it is and listed (`upgrade: left as is:
...`), and the script then exits 1, after writing the file.

The rules:
  - parameter names camelCase -> snake_case as Mitsuba 3's own parser
    upgrades files of version < 2 (`toWorld` -> `to_world`, `intIOR` ->
    `int_ior`, `sampleCount` -> `sample_count`), and a diffuse BSDF's
    `diffuseReflectance` -> `reflectance`;
  - `<lookAt>` -> `<lookat>`; `<srgb>` -> `<rgb>` with the colour
    linearised (sRGB curve); `<blackbody>` -> `<spectrum type="blackbody">`;
    the `intent` attribute of colours dropped (Mitsuba 3 knows it from the
    parameter);
  - textures: `ldrtexture` -> `bitmap`; `uoffset`/`voffset`/`uscale`/`vscale`
    -> a `to_uv` transform (scale after translation, as Mitsuba 3's
    upgrade); `filterType` `trilinear`/`ewa` -> `bilinear` (Mitsuba 3 has no
    MIP maps); `gamma` 1 -> `raw` true, other gammas, `maxAnisotropy` and
    `cache` dropped; wrap modes `zero`/`one` -> `clamp`;
  - BSDFs Mitsuba 3 lacks, to their nearest equivalent: `roughdiffuse` ->
    `diffuse` (Oren-Nayar roughness dropped); `phong` -> `roughplastic`,
    Beckmann with alpha = sqrt(2 / (exponent + 2)) (the Phong lobe's
    matching Beckmann roughness), its diffuse and specular reflectances;
    `ward` -> `roughplastic`, Beckmann with alpha = sqrt(alphaU alphaV);
    `coating`/`roughcoating` -> the BSDF they coat; `mixturebsdf` of two
    BSDFs -> `blendbsdf` (weight w2 / (w1 + w2)); microfacet distributions
    `phong` -> `beckmann` and `as` -> `ggx`; a conductor's `extEta` dropped;
  - `sunsky`: Mitsuba 3's sunsky, y-up as in 0.6 (a `to_world` turning
    Mitsuba 3's z-up sky), `sunRadiusScale` -> `sun_aperture` (0.5358
    degrees times it), `stretch`, `extend` dropped; then, as 0.6 itself
    drew its sunsky into an environment map of `resolution` (512) x 256
    pixels, rasterised into that `envmap` (OUTPUT-sky.exr beside the
    output; sunsky_envmap.py, which needs Mitsuba 3's llvm_ad_rgb), since
    trilux reads `envmap` and not Mitsuba 3's sunsky; `--sunsky keep` keeps
    the sunsky element instead;
  - shapes: `maxSmoothAngle` -> `face_normals` true (Mitsuba 3 has no crease
    angle);
  - films: `ldrfilm` -> `hdrfilm`; the tone-mapping parameters (`gamma`,
    `exposure`, `tonemapMethod`, `key`, `burn`), `banner`,
    `highQualityEdges` and `attachLog` dropped;
  - samplers `halton`, `hammersley`, `sobol` -> `independent` (`scramble`,
    `dimension` dropped);
  - integrators other than `path`, `volpath`, `direct` and `ptracer` ->
    `path` (its `maxDepth` kept; `$name`s in the integrator resolved from
    the file's `<default>`s first, since the type decides the rest);
    `volpath_simple` -> `volpath`; `strictNormals` dropped;
  - the scene's version -> 3.0.0.
"""
import argparse
import math
import pathlib
import re
import sys
import xml.etree.ElementTree as ET

# Plugins of Mitsuba 0.6 that Mitsuba 3 also has under the same name.
SAME = {
    "bsdf": {"diffuse", "dielectric", "thindielectric", "roughdielectric", "conductor",
             "roughconductor", "plastic", "roughplastic", "bumpmap", "normalmap", "blendbsdf",
             "mask", "twosided", "null"},
    "texture": {"bitmap", "checkerboard", "mesh_attribute"},
    "integrator": {"path", "volpath", "direct", "ptracer", "aov"},
    "sampler": {"independent", "stratified", "multijitter", "ldsampler", "orthogonal"},
    "film": {"hdrfilm"},
    "emitter": {"area", "point", "spot", "directional", "constant", "envmap", "sunsky"},
}
# Mitsuba 3's sunsky default `sun_aperture` (degrees), which 0.6's
# `sunRadiusScale` multiplies.
SUN_APERTURE = 0.5358
FILM_DROPPED = ["gamma", "exposure", "tonemap_method", "key", "burn", "banner",
                "high_quality_edges", "attach_log"]


def snake(name):
    """Mitsuba 3's camel_to_underscore_case (src/core/parser.cpp)."""
    out, i = [], 0
    while i < len(name):
        c = name[i]
        if i > 0 and name[i - 1].islower() and c.isupper():
            out.append("_" + c.lower())
            while i + 1 < len(name) and name[i + 1].isupper():
                i += 1
                out.append(name[i].lower())
        else:
            out.append(c)
        i += 1
    return "".join(out)


def srgb_to_linear(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def describe(e):
    attrs = "".join(f' {k}="{e.get(k)}"' for k in ("type", "id", "name") if e.get(k))
    return f"<{e.tag}{attrs}>"


class Upgrade:
    """One file's upgrade: the tree changed in place, the changes listed."""

    def __init__(self, root, rasterise_sky=None):
        self.root = root
        self.rasterise_sky = rasterise_sky
        self.renames = {}
        self.unsupported = []
        self.defaults = {d.get("name"): d.get("value") for d in root.iter("default")}
        self.parents = {c: p for p in root.iter() for c in p}

    def note(self, message):
        print(f"upgrade: {message}", file=sys.stderr)

    def params(self, e):
        """The parameter elements of `e`, by name."""
        return {c.get("name"): c for c in e if c.get("name") is not None}

    def value(self, e, name, default=None):
        p = self.params(e).get(name)
        return float(p.get("value")) if p is not None and p.get("value") is not None else default

    def drop(self, e, names, why):
        for name in names:
            p = self.params(e).get(name)
            if p is not None:
                e.remove(p)
                self.note(f"{describe(e)}: {name} dropped ({why})")

    def set_param(self, e, tag, name, value):
        p = self.params(e).get(name)
        if p is None:
            p = ET.SubElement(e, tag)
        p.tag = tag
        p.attrib = {"name": name, "value": value}

    def retype(self, e, new, why):
        self.note(f"{describe(e)} -> type \"{new}\" ({why})")
        e.set("type", new)

    def run(self):
        version = self.root.get("version")
        self.root.set("version", "3.0.0")
        self.note(f"scene version {version} -> 3.0.0")
        # Names first: the plugin rules read the parameters by their new
        # names.
        for e in list(self.root.iter()):
            self.element(e)
        for e in list(self.root.iter()):
            handler = getattr(self, "plugin_" + e.tag, None)
            if handler is not None and e.get("type") is not None:
                handler(e)
        for (old, new), n in sorted(self.renames.items()):
            self.note(f"parameter {old} -> {new} ({n}x)")

    def element(self, e):
        name = e.get("name")
        if name is not None and e.tag not in ("default",):
            new = snake(name)
            if new != name:
                e.set("name", new)
                self.renames[(name, new)] = self.renames.get((name, new), 0) + 1
        if e.tag == "lookAt":
            e.tag = "lookat"
            self.note("<lookAt> -> <lookat>")
        elif e.tag == "srgb":
            self.srgb(e)
        elif e.tag == "blackbody":
            self.blackbody(e)
        elif e.tag in ("rgb", "spectrum") and "intent" in e.attrib:
            del e.attrib["intent"]
        elif e.tag == "include":
            self.note(f"{describe(e)} {e.get('filename')}: upgrade the included file too")

    def srgb(self, e):
        text = e.get("value", "").strip()
        if text.startswith("#"):
            h = text[1:]
            rgb = [int(h[i:i + 2], 16) / 255 for i in (0, 2, 4)]
        else:
            rgb = [float(x) for x in re.split(r"[,\s]+", text) if x]
            rgb = rgb * 3 if len(rgb) == 1 else rgb
        lin = ", ".join(f"{srgb_to_linear(c):.6g}" for c in rgb)
        self.note(f"<srgb name=\"{e.get('name')}\" value=\"{text}\"> -> <rgb value=\"{lin}\"> (linearised)")
        e.tag = "rgb"
        e.attrib = {"name": e.get("name"), "value": lin}

    def blackbody(self, e):
        t = e.get("temperature", "6504").rstrip("kK")
        scale = e.get("multiplier")
        e.tag = "spectrum"
        e.attrib = {"name": e.get("name"), "type": "blackbody"}
        ET.SubElement(e, "float", {"name": "temperature", "value": t})
        self.note(f"<blackbody> -> <spectrum type=\"blackbody\"> ({t} K)")
        if scale not in (None, "1"):
            self.note(f"<blackbody> multiplier {scale} dropped (Mitsuba 3's blackbody has none)")

    def plugin_bsdf(self, e):
        t = e.get("type")
        dist = self.params(e).get("distribution")
        if dist is not None and dist.get("value") in ("phong", "as"):
            new = {"phong": "beckmann", "as": "ggx"}[dist.get("value")]
            self.note(f"{describe(e)}: distribution {dist.get('value')} -> {new} (Mitsuba 3 has beckmann and ggx)")
            dist.set("value", new)
        if t == "diffuse" and "diffuse_reflectance" in self.params(e):
            self.params(e)["diffuse_reflectance"].set("name", "reflectance")
        elif t == "roughdiffuse":
            self.retype(e, "diffuse", "Mitsuba 3 has no roughdiffuse; the Oren-Nayar roughness is dropped")
            if "diffuse_reflectance" in self.params(e):
                self.params(e)["diffuse_reflectance"].set("name", "reflectance")
            self.drop(e, ["alpha", "distribution", "use_fast_approx"], "diffuse has no roughness")
        elif t == "phong":
            n = self.value(e, "exponent", 30.0)
            alpha = math.sqrt(2.0 / (n + 2.0))
            self.retype(e, "roughplastic", f"Mitsuba 3 has no phong; Beckmann alpha {alpha:.4g} = sqrt(2/(exponent {n:g} + 2))")
            self.drop(e, ["exponent"], "replaced by alpha")
            self.set_param(e, "float", "alpha", f"{alpha:.6g}")
            self.set_param(e, "string", "distribution", "beckmann")
        elif t == "ward":
            au, av = self.value(e, "alpha_u", 0.1), self.value(e, "alpha_v", 0.1)
            alpha = math.sqrt(au * av)
            self.retype(e, "roughplastic", f"Mitsuba 3 has no ward; Beckmann alpha {alpha:.4g} = sqrt(alphaU alphaV)")
            self.drop(e, ["alpha_u", "alpha_v", "variant"], "replaced by alpha")
            self.set_param(e, "float", "alpha", f"{alpha:.6g}")
            self.set_param(e, "string", "distribution", "beckmann")
        elif t in ("coating", "roughcoating"):
            self.uncoat(e)
        elif t == "mixturebsdf":
            self.mixture(e)
        elif t in ("conductor", "roughconductor"):
            self.drop(e, ["ext_eta"], "Mitsuba 3's conductors are in vacuum")
        elif t not in SAME["bsdf"]:
            self.unsupported.append(describe(e))

    def uncoat(self, e):
        inner = [c for c in e if c.tag in ("bsdf", "ref")]
        if len(inner) != 1:
            self.unsupported.append(describe(e))
            return
        self.note(f"{describe(e)} -> the BSDF it coats (Mitsuba 3 has no coating)")
        c = inner[0]
        keep = {k: v for k, v in e.attrib.items() if k in ("id", "name")}
        e.clear()
        e.tag, e.text, e.tail = c.tag, c.text, e.tail
        e.attrib.update(c.attrib)
        e.attrib.update(keep)
        e.extend(list(c))

    def mixture(self, e):
        inner = [c for c in e if c.tag in ("bsdf", "ref")]
        weights = self.params(e).get("weights")
        if len(inner) != 2 or weights is None:
            self.unsupported.append(describe(e))
            return
        w = [float(x) for x in re.split(r"[,\s]+", weights.get("value").strip()) if x]
        e.remove(weights)
        self.retype(e, "blendbsdf", f"a mixture of two; weight {w[1]:g}/({w[0]:g}+{w[1]:g})")
        self.set_param(e, "float", "weight", f"{w[1] / (w[0] + w[1]):.6g}")

    def plugin_texture(self, e):
        if e.get("type") == "ldrtexture":
            self.retype(e, "bitmap", "Mitsuba 3's name")
        if e.get("type") not in SAME["texture"]:
            self.unsupported.append(describe(e))
        if e.get("type") != "bitmap" and e.get("type") != "checkerboard":
            return
        p = self.params(e)
        f = p.get("filter_type")
        if f is not None and f.get("value") in ("trilinear", "ewa"):
            self.note(f"{describe(e)}: filter_type {f.get('value')} -> bilinear (Mitsuba 3 has no MIP maps)")
            f.set("value", "bilinear")
        g = p.get("gamma")
        if g is not None:
            e.remove(g)
            if float(g.get("value")) == 1.0:
                self.set_param(e, "boolean", "raw", "true")
                self.note(f"{describe(e)}: gamma 1 -> raw true")
            else:
                self.note(f"{describe(e)}: gamma {g.get('value')} dropped (Mitsuba 3 decodes sRGB or nothing)")
        for mode in ("wrap_mode", "wrap_mode_u", "wrap_mode_v"):
            m = p.get(mode)
            if m is not None and m.get("value") in ("zero", "one"):
                self.note(f"{describe(e)}: {mode} {m.get('value')} -> clamp")
                m.set("value", "clamp")
        u, v = p.get("wrap_mode_u"), p.get("wrap_mode_v")
        if u is not None and v is not None and u.get("value") == v.get("value"):
            e.remove(v)
            u.set("name", "wrap_mode")
            self.note(f"{describe(e)}: wrap_mode_u = wrap_mode_v -> wrap_mode")
        self.drop(e, ["max_anisotropy", "cache"], "Mitsuba 3 has no such parameter")
        self.uv_transform(e)

    def uv_transform(self, e):
        names = ("uoffset", "voffset", "uscale", "vscale")
        v = {n: self.value(e, n) for n in names}
        if all(x is None for x in v.values()):
            return
        for n in names:
            if v[n] is not None:
                e.remove(self.params(e)[n])
        t = ET.SubElement(e, "transform", {"name": "to_uv"})
        off = (v["uoffset"] or 0.0, v["voffset"] or 0.0)
        sc = (1.0 if v["uscale"] is None else v["uscale"], 1.0 if v["vscale"] is None else v["vscale"])
        ET.SubElement(t, "translate", {"x": f"{off[0]:g}", "y": f"{off[1]:g}"})
        ET.SubElement(t, "scale", {"x": f"{sc[0]:g}", "y": f"{sc[1]:g}"})
        self.note(f"{describe(e)}: uoffset/voffset/uscale/vscale -> to_uv (translate {off[0]:g},{off[1]:g} then scale {sc[0]:g},{sc[1]:g})")

    def plugin_shape(self, e):
        if "max_smooth_angle" in self.params(e):
            self.drop(e, ["max_smooth_angle"], "Mitsuba 3 has no crease angle")
            self.set_param(e, "boolean", "face_normals", "true")
            self.note(f"{describe(e)}: face_normals true (the nearest to a crease angle)")

    def plugin_film(self, e):
        if e.get("type") == "ldrfilm":
            self.retype(e, "hdrfilm", "Mitsuba 3 writes linear images; tone mapping is the viewer's")
        elif e.get("type") not in SAME["film"]:
            self.unsupported.append(describe(e))
        self.drop(e, FILM_DROPPED, "Mitsuba 3's hdrfilm has no such parameter")

    def plugin_sampler(self, e):
        if e.get("type") in ("halton", "hammersley", "sobol"):
            self.retype(e, "independent", "Mitsuba 3 has no such sampler")
            self.drop(e, ["scramble"], "independent has no such parameter")
        elif e.get("type") not in SAME["sampler"]:
            self.unsupported.append(describe(e))
        self.drop(e, ["dimension"], "Mitsuba 3's samplers have no such parameter")

    def plugin_emitter(self, e):
        if e.get("type") not in SAME["emitter"]:
            self.unsupported.append(describe(e))
        if e.get("type") == "sunsky":
            self.upgrade_sunsky(e)

    def upgrade_sunsky(self, e):
        """Mitsuba 3's `sunsky` with 0.6's parameters, then (with a sky
        rasteriser) the `envmap` 0.6 itself drew it into."""
        scale = self.value(e, "sun_radius_scale")
        if scale is not None:
            self.set_param(e, "float", "sun_aperture", f"{SUN_APERTURE * scale:g}")
            self.note(f"{describe(e)}: sun_radius_scale {scale:g} -> sun_aperture {SUN_APERTURE * scale:g} degrees")
        width = int(self.value(e, "resolution", 512))
        self.drop(e, ["sun_radius_scale", "stretch", "resolution", "extend"],
                  "Mitsuba 3's sunsky has no such parameter")
        if "to_world" not in self.params(e):
            t = ET.SubElement(e, "transform", {"name": "to_world"})
            ET.SubElement(t, "rotate", {"x": "1", "angle": "-90"})
            self.note(f"{describe(e)}: to_world rotate x -90 (0.6's sky is y-up, Mitsuba 3's z-up)")
        if self.rasterise_sky is None:
            return
        name = self.rasterise_sky(ET.tostring(e, encoding="unicode"), width)
        tail = e.tail
        e.clear()
        e.tail = tail
        e.set("type", "envmap")
        ET.SubElement(e, "string", {"name": "filename", "value": name})
        self.note(f'<emitter type="sunsky"> -> type "envmap" {name}, {width} x {width // 2} '
                  "(Mitsuba 3's sunsky rasterised, as 0.6 drew its sunsky into an envmap)")

    def plugin_integrator(self, e):
        for x in e.iter():
            for k, v in x.attrib.items():
                if "$" in v:
                    new = re.sub(r"\$(\w+)", lambda m: self.defaults.get(m.group(1), m.group(0)), v)
                    self.note(f"{describe(x)}: {k} {v} -> {new} (the file's <default>)")
                    x.set(k, new)
        t = e.get("type")
        if t == "volpath_simple":
            self.retype(e, "volpath", "Mitsuba 3's name")
        elif t not in SAME["integrator"]:
            self.retype(e, "path", f"Mitsuba 3 has no {t}")
            keep = {"max_depth", "rr_depth", "hide_emitters"}
            self.drop(e, [n for n in self.params(e) if n not in keep], "path has no such parameter")
        self.drop(e, ["strict_normals"], "Mitsuba 3's path has no such parameter")


def upgrade(text, rasterise_sky=None):
    """The upgraded XML of a Mitsuba 0.6 file's `text`, and the plugins
    left as they are. `rasterise_sky(sunsky_xml, width)`, when given,
    writes a sunsky's envmap and returns its file name."""
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    root = ET.fromstring(text, parser=parser)
    if root.tag != "scene":
        raise ValueError(f"the root element is <{root.tag}>, not <scene>")
    u = Upgrade(root, rasterise_sky)
    u.run()
    body = ET.tostring(root, encoding="unicode")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + body + "\n", u.unsupported


def sky_rasteriser(args):
    """The sunsky rasteriser for `--sunsky envmap`: writes OUTPUT-sky.exr
    (-sky2.exr, ... for more skies) beside the output file."""
    if args.sunsky == "keep":
        return None
    written = []

    def rasterise(sunsky_xml, width):
        if not args.output:
            raise ValueError("a sunsky becomes an envmap image beside the output: give -o, "
                             "or --sunsky keep")
        import sunsky_envmap
        out = pathlib.Path(args.output)
        name = f"{out.stem}-sky{len(written) + 1 if written else ''}.exr"
        sunsky_envmap.rasterise(sunsky_xml, out.parent / name, width)
        written.append(name)
        return name

    return rasterise


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", help="a Mitsuba 0.6 scene file")
    ap.add_argument("-o", "--output", help="the Mitsuba 3 file (default: stdout)")
    ap.add_argument("--sunsky", choices=["envmap", "keep"], default="envmap",
                    help="a sunsky becomes the envmap it rasterises to, beside the output "
                         "(the default: trilux reads envmap, not sunsky), or stays Mitsuba 3's sunsky")
    args = ap.parse_args()
    try:
        with open(args.scene, encoding="utf-8") as f:
            text, unsupported = upgrade(f.read(), sky_rasteriser(args))
    except (OSError, ET.ParseError, ValueError, RuntimeError) as e:
        print(f"error: {args.scene}: {e}", file=sys.stderr)
        return 1
    if args.output:
        with open(args.output, "w", encoding="utf-8") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    for what in unsupported:
        print(f"upgrade: left as is: {what} (Mitsuba 3 has no equivalent)", file=sys.stderr)
    return 1 if unsupported else 0


if __name__ == "__main__":
    sys.exit(main())
