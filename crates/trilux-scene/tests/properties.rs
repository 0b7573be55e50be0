//! Property tests: bad input is an error value, never a panic; numbers and
//! transforms survive the trip through XML text.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec3};
use proptest::prelude::*;
use trilux_color::ColorParam;
use trilux_scene::load_str;

const SCENE: &str = include_str!("../../../scenes/cornell-box.xml");

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Cutting, deleting or replacing bytes anywhere in a valid scene gives
    /// either a scene or an error, never a panic; an error displays one
    /// line per independent error (at most 20 and a count), each starting
    /// with the file name.
    #[test]
    fn mutated_scenes_never_panic(at in 0usize..SCENE.len(), len in 0usize..40, with in "[<>\"=/a-z0-9 .,:$-]{0,6}") {
        let mut bytes = SCENE.as_bytes().to_vec();
        let end = (at + len).min(bytes.len());
        bytes.splice(at..end, with.bytes());
        let text = String::from_utf8_lossy(&bytes);
        if let Err(e) = load_str(&text, "mutated.xml") {
            let msg = e.to_string();
            for line in msg.lines() {
                prop_assert!(line.starts_with("mutated.xml:"), "{}", msg);
            }
            prop_assert!((1..=21).contains(&msg.lines().count()), "{}", msg);
        }
    }

    /// Any finite float written with Rust's shortest representation reads
    /// back exactly.
    #[test]
    fn floats_round_trip(v in 0.0f64..1.0) {
        let body = format!(r#"<scene version="3.0.0"><shape type="rectangle"><bsdf type="diffuse"><float name="reflectance" value="{v}"/></bsdf></shape></scene>"#);
        let s = load_str(&body, "f.xml").map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(&s.shapes[0].bsdf, &trilux_brdf::BsdfParams::Diffuse { reflectance: ColorParam::Float(v) });
    }

    /// translate · rotate · scale written in the file acts on points as the
    /// same product built with glam, applied right to left.
    #[test]
    fn transforms_compose_in_written_order(
        s in prop::array::uniform3(0.1f64..3.0),
        axis in prop::sample::select(vec![DVec3::X, DVec3::Y, DVec3::Z]),
        angle in -180.0f64..180.0,
        t in prop::array::uniform3(-5.0f64..5.0),
        p in prop::array::uniform3(-2.0f64..2.0),
    ) {
        let body = format!(
            r#"<scene version="3.0.0"><shape type="rectangle"><transform name="to_world">
               <scale x="{}" y="{}" z="{}"/><rotate x="{}" y="{}" z="{}" angle="{angle}"/>
               <translate x="{}" y="{}" z="{}"/></transform></shape></scene>"#,
            s[0], s[1], s[2], axis.x, axis.y, axis.z, t[0], t[1], t[2]
        );
        let scene = load_str(&body, "t.xml").map_err(|e| TestCaseError::fail(e.to_string()))?;
        let m = scene.shapes[0].shape.world_from_object;
        let expected = DMat4::from_translation(DVec3::from_array(t))
            * DMat4::from_axis_angle(axis, angle.to_radians())
            * DMat4::from_scale(DVec3::from_array(s));
        let p = DVec3::from_array(p);
        prop_assert!(m.transform_point3(p).distance(expected.transform_point3(p)) < 1e-9);
    }
}
