//! Mutated solution files: 12 000 corruptions of a real file —
//! bit flips, random and extreme integers, NaN, infinite and negative
//! floats, truncations, insertions, deletions — nine in ten with the
//! header's length and checksum recomputed so that the parser itself is
//! exercised. Each one is refused with a message or accepted as a valid
//! solution that answers queries; none panics, and none makes the reader
//! hold more than twice the memory of loading the intact file (a counting
//! allocator measures every case and refuses any single request above 256
//! MiB outright).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

#[path = "../../../tests/support/capped_alloc.rs"]
mod capped_alloc;
mod common;

use std::sync::Arc;

use capped_alloc::{Capped, Rng, peak, reset_peak};
use glam::DVec2;
use trilux_geometry::{FaceId, Side, SurfaceId};
use trilux_solver::{PreparedScene, Quality, Solution, SolverSettings, SurfaceSite};

#[global_allocator]
static ALLOCATOR: Capped = Capped;

/// A closed box with a glossy plate inside: the file holds Lambertian
/// radiance and stored interaction hierarchies.
const SCENE: &str = r#"<scene version="3.0.0">
  <shape type="cube"><boolean name="flip_normals" value="true"/>
    <bsdf type="diffuse"><float name="reflectance" value="0.6"/></bsdf>
  </shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><translate z="0.99"/></transform>
    <boolean name="flip_normals" value="true"/>
    <emitter type="area"><float name="radiance" value="5"/></emitter>
  </shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="-70"/><translate z="-0.5"/></transform>
    <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf>
  </shape>
</scene>"#;

const HEADER: usize = 40;
const CASES: usize = 12_000;

fn fnv(bytes: &[u8]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// Writes the payload length and checksum the header should have.
fn fix_header(bytes: &mut [u8]) {
    if bytes.len() < HEADER {
        return;
    }
    let len = (bytes.len() - HEADER) as u64;
    let sum = fnv(&bytes[HEADER..]);
    bytes[24..32].copy_from_slice(&len.to_le_bytes());
    bytes[32..40].copy_from_slice(&sum.to_le_bytes());
}

/// One random corruption of `b` (mostly in the payload).
fn mutate(rng: &mut Rng, b: &mut Vec<u8>) {
    let at = |rng: &mut Rng, b: &Vec<u8>, width: usize| {
        let lo = if rng.below(20) == 0 { 0 } else { HEADER };
        lo + rng.below(b.len().saturating_sub(lo + width).max(1))
    };
    let put = |b: &mut Vec<u8>, i: usize, v: &[u8]| {
        if i + v.len() <= b.len() {
            b[i..i + v.len()].copy_from_slice(v);
        }
    };
    match rng.below(10) {
        0 => {
            let i = at(rng, b, 1);
            b[i] ^= 1 << rng.below(8);
        }
        1 => {
            let i = at(rng, b, 1);
            b[i] = rng.next() as u8;
        }
        2 => {
            let v = [
                0u32,
                1,
                2,
                3,
                4,
                5,
                0xFFFF_FFFF,
                0x7FFF_FFFF,
                0x8000_0000,
                1 << 20,
                1 << 28,
            ];
            let i = at(rng, b, 4);
            put(b, i, &v[rng.below(v.len())].to_le_bytes());
        }
        3 => {
            let v = [0u64, 1, u64::MAX, 1 << 40, 1 << 62, 0x7FF0_0000_0000_0000];
            let i = at(rng, b, 8);
            put(b, i, &v[rng.below(v.len())].to_le_bytes());
        }
        4 => {
            let v = [
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                -1.0,
                -0.0,
                f32::MAX,
                1e-45,
            ];
            let i = at(rng, b, 4);
            put(b, i, &v[rng.below(v.len())].to_le_bytes());
        }
        5 => {
            let v = [f64::NAN, f64::INFINITY, -1.0, f64::MAX, 5e-324];
            let i = at(rng, b, 8);
            put(b, i, &v[rng.below(v.len())].to_le_bytes());
        }
        6 => b.truncate(rng.below(b.len() + 1)),
        7 => {
            let i = at(rng, b, 1);
            let n = (1 + rng.below(64)).min(b.len() - i);
            b.drain(i..i + n);
        }
        8 => {
            let i = at(rng, b, 0).min(b.len());
            let n = 1 + rng.below(64);
            let bytes: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
            b.splice(i..i, bytes);
        }
        _ => {
            let i = at(rng, b, 1);
            let n = (1 + rng.below(64)).min(b.len() - i);
            let copy = b[i..i + n].to_vec();
            let j = at(rng, b, 0).min(b.len());
            b.splice(j..j, copy);
        }
    }
}

/// Queries an accepted solution everywhere it could be asked.
fn exercise(s: &Solution<3>, rng: &mut Rng) {
    assert!(
        s.min_radiance() >= 0.0,
        "an accepted solution is finite and non-negative"
    );
    let _ = s.interaction_counts();
    let surfaces = s.forest().geometry().surfaces().len() as u32;
    for _ in 0..8 {
        let site = |rng: &mut Rng| {
            let surface = SurfaceId(rng.below(surfaces as usize) as u32);
            let u = DVec2::new(
                rng.below(1000) as f64 / 1000.0,
                rng.below(1000) as f64 / 1000.0,
            );
            let side = if rng.below(2) == 0 {
                Side::Front
            } else {
                Side::Back
            };
            SurfaceSite::new(surface, side, s.forest().sample_surface(surface, u).coord)
        };
        let (a, b) = (site(rng), site(rng));
        assert!(s.radiance(&a, &b).is_finite());
        let _ = s.surface_mean_radiance(FaceId::new(a.face.surface(), a.face.side()));
    }
}

#[test]
fn mutated_solution_files_never_panic_nor_allocate_beyond_twice_the_intact_load() {
    let scene = trilux_scene::load_str(SCENE, "fuzz.xml").unwrap();
    let prepared: Arc<PreparedScene<3>> = common::prepare_scene(&scene);
    let settings = SolverSettings::preset(Quality::Draft);
    let solution = trilux_solver::Solver::new(Arc::clone(&prepared), settings.clone())
        .unwrap()
        .solve(|_| {});
    let (hierarchies, nodes) = solution.interaction_counts();
    assert!(
        hierarchies > 0 && nodes > hierarchies,
        "the file exercises stored interactions"
    );
    let intact = solution.to_bytes().unwrap();
    drop(solution);

    let base = reset_peak();
    let s = Solution::from_bytes(&intact, Arc::clone(&prepared), &settings).unwrap();
    let intact_peak = peak() - base;
    drop(s);
    let bound = 2 * intact_peak;

    // Every depth limit set to values a corrupt file might hold (the old
    // format allocated 4^depth elements from one): refused, cheaply.
    let stats_len = u64::from_le_bytes(intact[HEADER..HEADER + 8].try_into().unwrap()) as usize;
    let depths_at = HEADER + 8 + stats_len;
    let surfaces = u32::from_le_bytes(intact[depths_at..depths_at + 4].try_into().unwrap());
    for k in 0..surfaces as usize {
        for v in [0u32, 9, 30, 1 << 20, u32::MAX] {
            let mut bytes = intact.clone();
            let at = depths_at + 4 + 4 * k;
            if bytes[at..at + 4] == v.to_le_bytes() {
                continue;
            }
            bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
            fix_header(&mut bytes);
            let base = reset_peak();
            let e = Solution::from_bytes(&bytes, Arc::clone(&prepared), &settings).err();
            assert!(peak() - base <= bound);
            assert_eq!(
                e.as_deref(),
                Some("element depth limits differ from the scene's")
            );
        }
    }

    let mut rng = Rng(14);
    let (mut accepted, mut refused) = (0, 0);
    for case in 0..CASES {
        let mut bytes = intact.clone();
        for _ in 0..1 + rng.below(3) {
            mutate(&mut rng, &mut bytes);
        }
        if rng.below(10) != 0 {
            fix_header(&mut bytes);
        }
        let base = reset_peak();
        let loaded = Solution::from_bytes(&bytes, Arc::clone(&prepared), &settings);
        let used = peak() - base;
        assert!(
            used <= bound,
            "case {case}: {used} bytes, the bound is {bound}"
        );
        match loaded {
            Ok(s) => {
                exercise(&s, &mut rng);
                accepted += 1;
            }
            Err(message) => {
                assert!(
                    !message.is_empty() && !message.contains('\n'),
                    "case {case}: {message:?}"
                );
                refused += 1;
            }
        }
    }
    // Most corruptions are caught; some (a flipped statistic, a changed but
    // valid radiance) are valid solutions.
    assert!(
        refused > CASES / 2,
        "{refused} refused, {accepted} accepted"
    );
    eprintln!(
        "{CASES} cases: {refused} refused, {accepted} accepted; intact load {intact_peak} bytes, bound {bound}"
    );
}
