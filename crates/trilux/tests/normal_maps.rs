//! Shading normals from textures through the binary (Mitsuba 3's
//! `normalmap` and `bumpmap`; trilux_brdf::normal_map): a closed form and
//! Mitsuba 3.9.1's images.
//!
//! - A constant normal map tilts a diffuse floor under a directional light:
//!   every pixel is ρ/π · E · (n′·ω_i) with n′ the map's normal in the
//!   floor's tangent frame (∂p/∂u, n × ∂p/∂u, n), exactly.
//! - The point-lit box of scenes/lights with a normal-mapped and a
//!   bump-mapped floor (scenes/normalmap; references by its
//!   make_references.py, 4096 spp in 16 passes, relative standard error of
//!   the means at most 0.03 %): the image mean within 1 % for the path
//!   gather and the control variate (the solve keeps the geometric normal;
//!   the render reads it with the turned one). Without the maps the same
//!   box is 3–4 % off (docs/results.md, "Normal and bump maps").
//! - Bad maps are one located line and exit 1.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use trilux_render::Image;

mod common;
use common::{folder, mean_rgb_sum as mean, reference_rgb, render, scene, trilux};

fn reference(name: &str) -> f64 {
    reference_rgb(&format!("normalmap/{name}.json"))
        .iter()
        .sum()
}

/// A floor (scenes/normalmap/floor.obj) with `bsdf`, under a directional
/// light of irradiance 2 travelling along −(1, 1, 1)/√3, seen from above.
fn floor_scene(bsdf: &str) -> String {
    let obj = scene("normalmap/floor.obj");
    format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world">
            <lookat origin="0, 2, 0" target="0, -1, 0" up="0, 0, -1"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="8"/>
            <integer name="height" value="8"/>
        </film>
    </sensor>
    <shape type="obj">
        <string name="filename" value="{obj}"/>
        {bsdf}
    </shape>
    <emitter type="directional">
        <vector name="direction" x="-1" y="-1" z="-1"/>
        <rgb name="irradiance" value="2, 2, 2"/>
    </emitter>
</scene>
"#
    )
}

fn normal_mapped(texture: &str) -> String {
    format!(
        r#"<bsdf type="normalmap">
            <texture type="bitmap" name="normalmap">
                <string name="filename" value="{texture}"/>
                <boolean name="raw" value="true"/>
            </texture>
            <bsdf type="diffuse">
                <float name="reflectance" value="0.5"/>
            </bsdf>
        </bsdf>"#
    )
}

/// Every pixel of the tilted floor is ρ/π · E · cos of the light to the
/// map's normal: n_l = normalize(2·rgb − 1) for the texel (191, 160, 230)
/// of scenes/normalmap/tilt.png, in the floor's frame s = ∂p/∂u = +x,
/// n = +y, t = n × s = −z. A mirrored frame (t = +z) or the untouched
/// normal gives another value.
#[test]
fn a_constant_normal_map_tilts_a_diffuse_floor_by_its_cosine() {
    let dir = folder("normalmap-tilt");
    let file = dir.join("tilt.xml");
    let tilt = scene("normalmap/tilt.png");
    std::fs::write(&file, floor_scene(&normal_mapped(&tilt))).unwrap();
    let img = render(
        file.to_str().unwrap(),
        &["--spp", "4", "--gather", "paths"],
        &dir.join("tilt.exr"),
    );
    let n = [191.0, 160.0, 230.0].map(|c: f64| 2.0 * c / 255.0 - 1.0);
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let world = [n[0] / len, n[2] / len, -n[1] / len];
    let cos = (world[0] + world[1] + world[2]) / 3f64.sqrt();
    let expected = 0.5 / std::f64::consts::PI * 2.0 * cos;
    let flat = 0.5 / std::f64::consts::PI * 2.0 / 3f64.sqrt();
    assert!((expected / flat - 1.0).abs() > 0.05, "the tilt shows");
    for p in img.pixels() {
        for c in p.iter().take(3) {
            let rel = f64::from(*c) / expected - 1.0;
            assert!(rel.abs() < 1e-5, "{c} vs {expected} (untilted {flat})");
        }
    }
}

/// Both boxes against Mitsuba, in the two unbiased gathers.
#[test]
fn normal_and_bump_mapped_floors_match_mitsuba() {
    let dir = folder("normalmap-mitsuba");
    let mut report = Vec::new();
    let mut ok = true;
    for name in ["normalmap-box", "bumpmap-box"] {
        let file = scene(&format!("normalmap/{name}.xml"));
        let sol = dir.join(format!("{name}.sol"));
        let run = trilux(&["solve", &file, "-o", sol.to_str().unwrap()]);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let r = reference(name);
        for gather in ["paths", "control"] {
            let out = dir.join(format!("{name}-{gather}.exr"));
            let args = ["render", &file, "--solution", sol.to_str().unwrap()];
            let extra = [
                "--spp",
                "16",
                "--gather",
                gather,
                "-o",
                out.to_str().unwrap(),
            ];
            let run = trilux(&[&args[..], &extra[..]].concat());
            assert!(
                run.status.success(),
                "{}",
                String::from_utf8_lossy(&run.stderr)
            );
            let rel = mean(&Image::read_exr(&out).unwrap()) / r - 1.0;
            ok &= rel.abs() <= 0.01; // false for NaN
            report.push(format!(
                "{name} {gather}: {:+.2} % (tolerance 1 %)",
                100.0 * rel
            ));
        }
    }
    eprintln!("{}", report.join("\n"));
    assert!(ok, "{}", report.join("\n"));
}

/// The stderr of `trilux solve` on the floor with `bsdf`, which must fail
/// with status 1 and one line.
fn refused(name: &str, bsdf: &str) -> String {
    let dir = folder(name);
    let file = dir.join("bad.xml");
    std::fs::write(&file, floor_scene(bsdf)).unwrap();
    let out = trilux(&["solve", file.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with(&format!("error: {}:", file.display())),
        "{stderr}"
    );
    stderr
}

/// A missing image, a grey image as a normal map, a scale that is not a
/// number: one located line each, exit 1.
#[test]
fn bad_normal_and_bump_maps_are_one_located_line() {
    let e = refused("normalmap-missing", &normal_mapped("no-such-map.png"));
    assert!(e.contains("cannot read image"), "{e}");
    let grey = scene("normalmap/height.png");
    let e = refused("normalmap-grey", &normal_mapped(&grey));
    assert!(
        e.contains("a normal map needs an RGB image, found 1 channel"),
        "{e}"
    );
    let nan = format!(
        r#"<bsdf type="bumpmap">
            <float name="scale" value="nan"/>
            <texture type="bitmap"><string name="filename" value="{grey}"/></texture>
            <bsdf type="diffuse"/>
        </bsdf>"#
    );
    let e = refused("bumpmap-nan", &nan);
    assert!(e.contains("NaN is not allowed"), "{e}");
}
