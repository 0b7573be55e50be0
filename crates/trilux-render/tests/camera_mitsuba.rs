//! The camera against Mitsuba 3's `perspective` sensor: directions from
//! `sensor.sample_ray`, recorded by `data/mitsuba_camera.py` (Mitsuba 3.9.1,
//! scalar_rgb). Tolerance 1e-5 on each direction component: Mitsuba
//! computes in f32 (ε ≈ 6e-8, a few operations), while a wrong convention
//! (flipped axis, wrong fov axis) changes directions by 1e-2 or more.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DVec2, DVec3};
use trilux_render::camera::look_at;
use trilux_render::{Camera, FovAxis};

fn nums(words: &[&str]) -> Vec<f64> {
    words
        .iter()
        .map(|w| w.parse::<f64>().expect("number"))
        .collect()
}

#[test]
fn camera_matches_mitsuba() {
    let text = include_str!("data/mitsuba_camera.txt");
    let mut cams: Vec<Camera> = Vec::new();
    let mut rays = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w[0] {
            "cam" => {
                // cam i fov F axis A w W h H origin x y z target x y z up x y z
                let fov: f64 = w[3].parse().unwrap();
                let axis = FovAxis::from_name(w[5]).unwrap();
                let (width, height): (u32, u32) = (w[7].parse().unwrap(), w[9].parse().unwrap());
                let o = nums(&w[11..14]);
                let t = nums(&w[15..18]);
                let u = nums(&w[19..22]);
                let m = look_at(
                    DVec3::from_slice(&o),
                    DVec3::from_slice(&t),
                    DVec3::from_slice(&u),
                )
                .unwrap();
                cams.push(Camera::new(m, fov, axis, width, height).unwrap());
            }
            "ray" => {
                let i: usize = w[1].parse().unwrap();
                let v = nums(&w[2..10]);
                let cam = &cams[i];
                let r = cam.ray_unit(DVec2::new(v[0], v[1]));
                let d = DVec3::new(v[5], v[6], v[7]);
                assert!(
                    (r.dir - d).abs().max_element() < 1e-5,
                    "camera {i} at ({}, {}): trilux {} vs Mitsuba {d}",
                    v[0],
                    v[1],
                    r.dir
                );
                // Mitsuba's origin lies on the same ray, at the near plane.
                let o = DVec3::new(v[2], v[3], v[4]);
                let off = o - r.origin;
                let miss = off.cross(r.dir).length();
                assert!(
                    miss < 1e-6 * (1.0 + r.origin.length()) * 10.0,
                    "camera {i}: origin off the ray by {miss}"
                );
                assert!(off.dot(r.dir) >= 0.0 && off.length() < 0.05);
                rays += 1;
            }
            _ => panic!("bad line {line}"),
        }
    }
    assert_eq!(rays, 64);
}

#[test]
fn film_pixels_map_to_positions() {
    // Pixel units and unit film positions agree.
    let m = look_at(DVec3::ZERO, DVec3::Z, DVec3::Y).unwrap();
    let cam = Camera::new(m, 50.0, FovAxis::X, 40, 20).unwrap();
    let a = cam.ray(DVec2::new(10.0, 5.0));
    let b = cam.ray_unit(DVec2::new(0.25, 0.25));
    assert!((a.dir - b.dir).length() < 1e-15);
    // The top-left of the film looks up and to the left (+x is left).
    assert!(b.dir.x > 0.0 && b.dir.y > 0.0);
}
