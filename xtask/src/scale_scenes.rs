//! Generated scenes for `cargo xtask scale` (and the golden scenes made
//! from them): Mitsuba 3 XML, with OBJ files beside it where a case has
//! meshes. Deterministic: the same case always writes the same files.
//!
//! - `boxes N`: a room 8 × 3 × 8 (x, y up, z), one 0.6 m square light
//!   under the ceiling, N boxes resting on the floor, every second one
//!   glossy (GGX, α = 0.2), the others diffuse;
//! - `meshes N`: the same room with N separate OBJ boxes (8 triangles a
//!   side, so 6 charts each), every second one glossy;
//! - `grid T`: the same room with one bumpy sheet of about T triangles
//!   (a stand-in for a scanned object) lying on the floor;
//! - `curtain`: a 5 × 3 × 4 room with a glossy floor, a pleated two-sided
//!   diffuse curtain of 8 192 triangles and five lights.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// One generated case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Case {
    /// N primitive boxes, half glossy.
    Boxes(u32),
    /// N separate OBJ boxes, half glossy.
    Meshes(u32),
    /// One bumpy sheet of about T triangles.
    Grid(u32),
    /// The curtain room.
    Curtain,
    /// paper-scene2 with its cylinder as `around` × `along` planar
    /// rectangles (the paper's Table 4, fine planar version).
    Facets(u32, u32),
}

impl Case {
    /// A file-name stem for the case.
    pub fn name(&self) -> String {
        match self {
            Case::Boxes(n) => format!("boxes-{n}"),
            Case::Meshes(n) => format!("meshes-{n}"),
            Case::Grid(t) => format!("grid-{t}"),
            Case::Curtain => "curtain".into(),
            Case::Facets(a, b) => format!("paper-scene2-facets-{}", a * b),
        }
    }
}

/// A small deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

const HEADER: &str = r#"<?xml version="1.0" encoding="utf-8"?>
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <default name="res" value="128"/>
    <integrator type="path"/>
"#;

fn sensor(out: &mut String, origin: [f64; 3], target: [f64; 3], fov: f64) {
    let _ = write!(
        out,
        r#"    <sensor type="perspective">
        <float name="fov" value="{fov}"/>
        <transform name="to_world">
            <lookat origin="{}, {}, {}" target="{}, {}, {}" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="$res"/>
        </film>
    </sensor>
"#,
        origin[0], origin[1], origin[2], target[0], target[1], target[2]
    );
}

fn diffuse(out: &mut String, id: &str, rgb: [f64; 3]) {
    let _ = writeln!(
        out,
        r#"    <bsdf type="diffuse" id="{id}"><rgb name="reflectance" value="{:.3}, {:.3}, {:.3}"/></bsdf>"#,
        rgb[0], rgb[1], rgb[2]
    );
}

fn glossy(out: &mut String, id: &str, rgb: [f64; 3], alpha: f64) {
    let _ = writeln!(
        out,
        r#"    <bsdf type="roughconductor" id="{id}"><string name="distribution" value="ggx"/><float name="alpha" value="{alpha}"/><string name="material" value="none"/><rgb name="specular_reflectance" value="{:.3}, {:.3}, {:.3}"/></bsdf>"#,
        rgb[0], rgb[1], rgb[2]
    );
}

/// A rectangle [-sx, sx] × [-sy, sy] turned by `rotate` (axis, degrees)
/// and moved to `at`.
fn rectangle(out: &mut String, s: [f64; 2], rotate: Option<(&str, f64)>, at: [f64; 3], bsdf: &str) {
    let rot = rotate.map_or(String::new(), |(axis, deg)| {
        format!(r#"<rotate {axis}="1" angle="{deg}"/>"#)
    });
    let _ = writeln!(
        out,
        r#"    <shape type="rectangle"><transform name="to_world"><scale x="{}" y="{}"/>{rot}<translate x="{}" y="{}" z="{}"/></transform><ref id="{bsdf}"/></shape>"#,
        s[0], s[1], at[0], at[1], at[2]
    );
}

fn light(out: &mut String, half: f64, at: [f64; 3], radiance: f64) {
    let _ = writeln!(
        out,
        r#"    <shape type="rectangle"><transform name="to_world"><scale x="{half}" y="{half}"/><rotate x="1" angle="90"/><translate x="{}" y="{}" z="{}"/></transform><ref id="black"/><emitter type="area"><rgb name="radiance" value="{radiance}, {radiance}, {radiance}"/></emitter></shape>"#,
        at[0], at[1], at[2]
    );
}

/// The six walls of the room [0, w] × [0, h] × [0, d], facing inwards.
fn room(out: &mut String, w: f64, h: f64, d: f64, floor: &str, wall: &str) {
    let (hw, hh, hd) = (w / 2.0, h / 2.0, d / 2.0);
    rectangle(out, [hw, hd], Some(("x", -90.0)), [hw, 0.0, hd], floor);
    rectangle(out, [hw, hd], Some(("x", 90.0)), [hw, h, hd], wall);
    rectangle(out, [hw, hh], None, [hw, hh, 0.0], wall);
    rectangle(out, [hw, hh], Some(("y", 180.0)), [hw, hh, d], wall);
    rectangle(out, [hd, hh], Some(("y", 90.0)), [0.0, hh, hd], wall);
    rectangle(out, [hd, hh], Some(("y", -90.0)), [w, hh, hd], wall);
}

/// Box centres and half extents on the floor of the 8 × 8 room: one per
/// cell of a ⌈√N⌉² grid, jittered, never touching each other.
fn boxes(n: u32) -> Vec<([f64; 3], [f64; 3])> {
    let mut rng = Rng(0x5EED_0000 + u64::from(n));
    let side = (f64::from(n)).sqrt().ceil().max(1.0) as u32;
    let cell = 7.0 / f64::from(side);
    (0..n)
        .map(|b| {
            let (i, j) = (b % side, b / side);
            let hx = cell * rng.range(0.12, 0.3);
            let hz = cell * rng.range(0.12, 0.3);
            let hy = rng.range(0.1, 0.35).min(1.2 * cell);
            let cx = 0.5 + cell * (f64::from(i) + 0.5) + rng.range(-0.15, 0.15) * cell;
            let cz = 0.5 + cell * (f64::from(j) + 0.5) + rng.range(-0.15, 0.15) * cell;
            ([cx, hy, cz], [hx, hy, hz])
        })
        .collect()
}

fn box_colour(rng: &mut Rng) -> [f64; 3] {
    [
        rng.range(0.2, 0.8),
        rng.range(0.2, 0.8),
        rng.range(0.2, 0.8),
    ]
}

/// An axis-aligned box as an OBJ mesh, each side 2 × 2 quads (8 triangles).
fn box_obj(c: [f64; 3], h: [f64; 3]) -> String {
    let mut s = String::new();
    let mut v = 0u32;
    // (normal axis, sign): the side's two tangent axes follow so that the
    // triangles wind counter-clockwise seen from outside.
    for (axis, sign) in [
        (0, 1.0),
        (0, -1.0),
        (1, 1.0),
        (1, -1.0),
        (2, 1.0),
        (2, -1.0),
    ] {
        let (a, b) = if sign > 0.0 {
            ((axis + 1) % 3, (axis + 2) % 3)
        } else {
            ((axis + 2) % 3, (axis + 1) % 3)
        };
        for j in 0..3 {
            for i in 0..3 {
                let mut p = c;
                p[axis] += sign * h[axis];
                p[a] += h[a] * (f64::from(i) - 1.0);
                p[b] += h[b] * (f64::from(j) - 1.0);
                let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
            }
        }
        for j in 0..2 {
            for i in 0..2 {
                let q = v + 1 + j * 3 + i;
                let _ = writeln!(s, "f {} {} {}", q, q + 1, q + 4);
                let _ = writeln!(s, "f {} {} {}", q, q + 4, q + 3);
            }
        }
        v += 9;
    }
    s
}

/// A bumpy sheet of about `triangles` triangles over the floor patch
/// [1, 7]², 0.4–0.9 m up (a hill of bumps: a stand-in for a scanned
/// object).
fn grid_obj(triangles: u32) -> String {
    let n = ((f64::from(triangles) / 2.0).sqrt().round() as u32).max(2);
    let mut s = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (u, w) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
            let (x, z) = (1.0 + 6.0 * u, 1.0 + 6.0 * w);
            let r2 = (u - 0.5).powi(2) + (w - 0.5).powi(2);
            let y = 0.4 + 0.5 * (-8.0 * r2).exp() + 0.04 * (23.0 * u).sin() * (19.0 * w).cos();
            let _ = writeln!(s, "v {x} {y} {z}");
        }
    }
    for j in 0..n {
        for i in 0..n {
            let q = j * (n + 1) + i + 1;
            // Counter-clockwise seen from above (+y).
            let _ = writeln!(s, "f {} {} {}", q, q + n + 1, q + 1);
            let _ = writeln!(s, "f {} {} {}", q + 1, q + n + 1, q + n + 2);
        }
    }
    s
}

/// The pleated curtain of the curtain case: `nu` × `nv` quads.
fn curtain_obj(nu: u32, nv: u32) -> String {
    let mut s = String::new();
    for j in 0..=nv {
        for i in 0..=nu {
            let (a, t) = (f64::from(i) / f64::from(nu), f64::from(j) / f64::from(nv));
            let z = 0.3 + 2.9 * a;
            let y = 0.25 + 2.65 * t;
            let amp = 0.16 + (0.08 - 0.16) * t;
            let x = 0.35 + amp * (2.0 * std::f64::consts::PI * 5.0 * a).sin();
            let _ = writeln!(s, "v {x} {y} {z}");
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let q = j * (nu + 1) + i + 1;
            // (a, d, c) and (a, c, b) with b = q + 1, c = q + nu + 2,
            // d = q + nu + 1: the normal has +x (the room side).
            let _ = writeln!(s, "f {} {} {}", q, q + nu + 1, q + nu + 2);
            let _ = writeln!(s, "f {} {} {}", q, q + nu + 2, q + 1);
        }
    }
    s
}

fn write(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// paper-scene2 (scenes/paper-scene2.xml) with the cylinder replaced by
/// `around` × `along` flat rectangles, each the chord facet of the
/// cylinder between two meridians (outward normals, like Mitsuba's
/// cylinder).
fn facets_xml(around: u32, along: u32) -> Result<String> {
    let path = crate::golden::root().join("scenes/paper-scene2.xml");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let start = text
        .find("    <!-- The glossy cylinder")
        .context("paper-scene2.xml has no cylinder comment")?;
    let end = text[start..]
        .find("</shape>")
        .map(|e| start + e + "</shape>".len())
        .context("paper-scene2.xml has no cylinder shape")?;
    let (x0, x1, yc, r) = (-1.1f64, 1.1f64, 0.45f64, 0.45f64);
    let mut facets = format!(
        "    <!-- The glossy cylinder as {around} x {along} planar facets (flat, chords of the circle). -->\n"
    );
    let half_w = r * (std::f64::consts::PI / f64::from(around)).sin();
    let dist = r * (std::f64::consts::PI / f64::from(around)).cos();
    let half_l = 0.5 * (x1 - x0) / f64::from(along);
    for a in 0..around {
        let phi = 2.0 * std::f64::consts::PI * (f64::from(a) + 0.5) / f64::from(around);
        // Outward normal (0, cos φ, sin φ) and tangent (0, sin φ, −cos φ),
        // so that x̂ × t = n (a right-handed frame).
        let (n, t) = ([0.0, phi.cos(), phi.sin()], [0.0, phi.sin(), -phi.cos()]);
        for b in 0..along {
            let cx = x0 + (2.0 * f64::from(b) + 1.0) * half_l;
            let c = [cx, yc + dist * n[1], dist * n[2]];
            // Row-major 4 × 4: columns x̂·half_l, t·half_w, n, c.
            let _ = writeln!(
                facets,
                r#"    <shape type="rectangle"><transform name="to_world"><matrix value="{} 0 0 {} 0 {} {} {} 0 {} {} {} 0 0 0 1"/></transform><ref id="glossy"/></shape>"#,
                half_l,
                c[0],
                t[1] * half_w,
                n[1],
                c[1],
                t[2] * half_w,
                n[2],
                c[2]
            );
        }
    }
    Ok(format!("{}{}{}", &text[..start], facets, &text[end..]))
}

/// Writes the case's scene (and meshes) into `dir`; returns the scene file.
pub fn write_case(case: Case, dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    if let Case::Facets(a, b) = case {
        let path = dir.join(format!("{}.xml", case.name()));
        write(&path, &facets_xml(a, b)?)?;
        return Ok(path);
    }
    let mut x = String::from(HEADER);
    let mut rng = Rng(0xC0FF_EE00);
    match case {
        Case::Boxes(n) | Case::Meshes(n) => {
            sensor(&mut x, [4.0, 2.6, 7.6], [4.0, 0.4, 3.0], 70.0);
            diffuse(&mut x, "floor", [0.55, 0.5, 0.45]);
            diffuse(&mut x, "wall", [0.7, 0.7, 0.7]);
            diffuse(&mut x, "black", [0.0, 0.0, 0.0]);
            room(&mut x, 8.0, 3.0, 8.0, "floor", "wall");
            light(&mut x, 0.3, [4.0, 2.99, 4.0], 30.0);
            for (b, (c, h)) in boxes(n).into_iter().enumerate() {
                let id = format!("box{b}");
                let colour = box_colour(&mut rng);
                if b % 2 == 1 {
                    glossy(&mut x, &id, colour, 0.2);
                } else {
                    diffuse(&mut x, &id, colour);
                }
                if let Case::Meshes(_) = case {
                    let file = format!("{}-{b}.obj", case.name());
                    write(&dir.join(&file), &box_obj(c, h))?;
                    let _ = writeln!(
                        x,
                        r#"    <shape type="obj"><string name="filename" value="{file}"/><boolean name="face_normals" value="true"/><ref id="{id}"/></shape>"#
                    );
                } else {
                    let _ = writeln!(
                        x,
                        r#"    <shape type="cube"><transform name="to_world"><scale x="{}" y="{}" z="{}"/><translate x="{}" y="{}" z="{}"/></transform><ref id="{id}"/></shape>"#,
                        h[0], h[1], h[2], c[0], c[1], c[2]
                    );
                }
            }
        }
        Case::Grid(t) => {
            sensor(&mut x, [4.0, 2.6, 7.6], [4.0, 0.4, 3.0], 70.0);
            diffuse(&mut x, "floor", [0.55, 0.5, 0.45]);
            diffuse(&mut x, "wall", [0.7, 0.7, 0.7]);
            diffuse(&mut x, "object", [0.6, 0.55, 0.5]);
            diffuse(&mut x, "black", [0.0, 0.0, 0.0]);
            room(&mut x, 8.0, 3.0, 8.0, "floor", "wall");
            light(&mut x, 0.3, [4.0, 2.99, 4.0], 30.0);
            let file = format!("{}.obj", case.name());
            write(&dir.join(&file), &grid_obj(t))?;
            let _ = writeln!(
                x,
                r#"    <shape type="obj"><string name="filename" value="{file}"/><boolean name="face_normals" value="true"/><ref id="object"/></shape>"#
            );
        }
        Case::Facets(..) => {}
        Case::Curtain => {
            sensor(&mut x, [4.6, 1.8, 3.7], [1.0, 1.0, 1.4], 70.0);
            diffuse(&mut x, "wall", [0.7, 0.68, 0.62]);
            let _ = writeln!(
                x,
                r#"    <bsdf type="blendbsdf" id="floor"><float name="weight" value="0.35"/><bsdf type="diffuse"><rgb name="reflectance" value="0.45, 0.35, 0.25"/></bsdf><bsdf type="roughconductor"><string name="distribution" value="ggx"/><float name="alpha" value="0.08"/><string name="material" value="none"/><rgb name="specular_reflectance" value="0.9, 0.9, 0.9"/></bsdf></bsdf>"#
            );
            let _ = writeln!(
                x,
                r#"    <bsdf type="twosided" id="curtain"><bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.12, 0.1"/></bsdf></bsdf>"#
            );
            diffuse(&mut x, "black", [0.0, 0.0, 0.0]);
            room(&mut x, 5.0, 3.0, 4.0, "floor", "wall");
            for (lx, lz) in [(1.3, 1.2), (3.7, 1.2), (2.5, 2.0), (1.3, 2.8), (3.7, 2.8)] {
                light(&mut x, 0.2, [lx, 2.99, lz], 8.0);
            }
            let file = "curtain-8192.obj";
            write(&dir.join(file), &curtain_obj(128, 32))?;
            let _ = writeln!(
                x,
                r#"    <shape type="obj"><string name="filename" value="{file}"/><ref id="curtain"/></shape>"#
            );
        }
    }
    x.push_str("</scene>\n");
    let path = dir.join(format!("{}.xml", case.name()));
    write(&path, &x)?;
    Ok(path)
}
