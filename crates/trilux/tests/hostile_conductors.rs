//! Conductors written wrong, through the binary: a conductor material
//! Mitsuba does not name, one given with `eta` or `k` as well, a NaN `eta`,
//! a `conductor` with a rough conductor's parameters, and a reflectance
//! above 1 each give one line `error: FILE:LINE:COL: ...` at the value
//! (status 1) before anything is solved. Negative `eta` and `k` are not
//! errors: Mitsuba takes them as published data write them
//! (crates/trilux-scene/tests/negative_ior.rs).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use std::time::Duration;

mod common;
use common::folder;
use common::hostile::{assert_refused, s, trilux_or_hang, write};

/// A scene whose one rectangle has the `<bsdf>` of line 3; the value
/// under test is on line 4, at column 5.
fn scene(bsdf: &str, value: &str) -> String {
    format!(
        "<scene version=\"3.0.0\">\n<shape type=\"rectangle\">\n<bsdf type=\"{bsdf}\">\n    {value}\n</bsdf>\n</shape>\n</scene>\n"
    )
}

#[test]
fn bad_conductors_are_located_errors() {
    let dir = folder("hostile-conductors");
    let cases = [
        (
            "conductor",
            r#"<string name="material" value="Copper"/>"#,
            "unknown conductor material \"Copper\"",
        ),
        (
            "roughconductor",
            r#"<string name="material" value="cu"/>"#,
            "unknown conductor material \"cu\"",
        ),
        (
            "conductor",
            r#"<float name="eta" value="1.2"/><string name="material" value="Au"/>"#,
            "give either material (\"Au\") or eta and k, not both",
        ),
        (
            "roughconductor",
            r#"<rgb name="k" value="3, 2, 1"/><string name="material" value="Ag"/>"#,
            "give either material (\"Ag\") or eta and k, not both",
        ),
        (
            "conductor",
            r#"<float name="eta" value="nan"/>"#,
            "NaN is not allowed here",
        ),
        (
            "conductor",
            r#"<float name="alpha" value="0.1"/>"#,
            "unknown parameter \"alpha\"",
        ),
        (
            "conductor",
            r#"<float name="specular_reflectance" value="1.5"/>"#,
            "specular_reflectance must not exceed 1",
        ),
    ];
    for (i, (bsdf, value, what)) in cases.iter().enumerate() {
        let path = write(&dir, &format!("bad{i}.xml"), scene(bsdf, value));
        let sol = dir.join(format!("bad{i}.sol"));
        for args in [
            vec!["info", s(&path)],
            vec!["solve", s(&path), "-o", s(&sol)],
        ] {
            let out = trilux_or_hang(&args, Duration::from_secs(60));
            assert_refused(&out, &format!("{}:4:", s(&path)), what);
        }
        assert!(!sol.exists(), "no solution left behind");
    }
}
