//! Mutated OBJ, PLY and serialized meshes and scene files: 12 000
//! corruptions of real OBJ files, 6 000 of ASCII and binary PLY files — bytes, tokens such as `1e30`, `nan`, `-7`, `99999999`
//! and whole lines of them —, 4 000 of Mitsuba serialized files (bytes and
//! counts of the decompressed stream, or of the compressed file), each
//! parsed and, when it parses, built into
//! geometry and a BVH; and 10 000 of the bundled Cornell box, loaded. None
//! panics; every refusal is one line; no case makes the loader hold more
//! than its stated bound (a counting allocator measures every case and
//! refuses any single request above 256 MiB outright):
//! - OBJ, PLY and serialized: 256 KiB + 256 bytes per byte of the file
//!   (serialized: of its decompressed stream), through
//!   `Geometry::build` (the worst case measured: 34 bytes per byte);
//! - scene: 1 MiB + 64 bytes per byte of the file (measured: 12).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

#[path = "../../../tests/support/capped_alloc.rs"]
mod capped_alloc;

use std::path::Path;

use capped_alloc::{Capped, Rng, peak, reset_peak};
use glam::DMat4;
use trilux_geometry::{Geometry, Shape, ShapeKind};
use trilux_scene::obj::parse_obj;
use trilux_scene::ply::parse_ply;
use trilux_scene::serialized::parse_serialized;

#[global_allocator]
static ALLOCATOR: Capped = Capped;

const OBJ_CASES: usize = 12_000;
const PLY_CASES: usize = 6_000;
const XML_CASES: usize = 10_000;
const SERIALIZED_CASES: usize = 4_000;

/// Valid seeds: a cube of quads with texture coordinates and normals,
/// negative (relative) indices, several objects, fans.
const SEEDS: [&str; 3] = [
    "# cube\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
     vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n\
     f 1/1/1 4/4/1 3/3/1 2/2/1\nf 5/1/2 6/2/2 7/3/2 8/4/2\nf 1/1/3 2/2/3 6/3/3 5/4/3\n\
     f 4/1/4 8/2/4 7/3/4 3/4/4\nf 1/1/5 5/2/5 8/3/5 4/4/5\nf 2/1/6 3/2/6 7/3/6 6/4/6\n",
    "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\no b\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf -4 -3 -2 -1\ng c\nusemtl x\nv 2 0 0\nv 3 0 0\nv 2 1 0\nf 8 9 10\n",
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 0.7\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nl 1 2\np 3\n",
];

/// Pieces a mutation inserts: OBJ syntax and extreme numbers.
const TOKENS: [&str; 24] = [
    " ",
    "\n",
    "/",
    "//",
    "-",
    ".",
    "e",
    "v ",
    "vn ",
    "vt ",
    "f ",
    "o x\n",
    "1e30",
    "-1e30",
    "nan",
    "inf",
    "0",
    "-7",
    "99999999",
    "4294967296",
    "1e-300",
    "\\\n",
    "#",
    "f 1 2 3\n",
];

/// Numbers a mutation writes over a number of the file.
const NUMBERS: [&str; 14] = [
    "1e30", "-1e30", "nan", "inf", "-inf", "0", "-0", "1e-300", "-7", "99999999", "3.4e38", "1e19",
    "1e16", "2",
];

/// One random change of `b`: a deletion, an insertion of a token, a byte,
/// a replacement by a token, or (half the time) a number of the file
/// replaced by an extreme one, which keeps the syntax and reaches the
/// numerical code.
fn mutate_text(rng: &mut Rng, b: &mut Vec<u8>, tokens: &[&str]) {
    let i = rng.below(b.len() + 1);
    if rng.below(2) == 0 {
        let is_num = |c: u8| c.is_ascii_digit() || c == b'.' || c == b'-';
        if let Some(start) = (i..b.len()).find(|&k| b[k].is_ascii_digit()) {
            let start = (0..start)
                .rev()
                .take_while(|&k| is_num(b[k]))
                .last()
                .unwrap_or(start);
            let end = (start..b.len()).find(|&k| !is_num(b[k])).unwrap_or(b.len());
            let n = NUMBERS[rng.below(NUMBERS.len())];
            b.splice(start..end, n.bytes());
        }
        return;
    }
    match rng.below(4) {
        0 => {
            let n = rng.below(8).min(b.len() - i);
            b.drain(i..i + n);
        }
        1 => {
            let t = tokens[rng.below(tokens.len())];
            b.splice(i..i, t.bytes());
        }
        2 if i < b.len() => b[i] = b"0123456789 -./\nvfe"[rng.below(18)],
        _ => {
            let n = rng.below(8).min(b.len() - i);
            let t = tokens[rng.below(tokens.len())];
            b.splice(i..i + n, t.bytes());
        }
    }
}

/// PLY seeds: ASCII (positions only) and binary (normals, texture
/// coordinates, a colour), little- and big-endian.
const PLY_SEEDS: [&[u8]; 3] = [
    include_bytes!("data/pyramid.ply"),
    include_bytes!("data/tent-le.ply"),
    include_bytes!("data/tent-be.ply"),
];

/// Pieces a mutation inserts into a PLY file: header words, counts.
const PLY_TOKENS: [&str; 16] = [
    " ",
    "\n",
    "element vertex 3\n",
    "element face 99999999\n",
    "property float x\n",
    "property list uchar int vertex_indices\n",
    "property list int double vertex_indices\n",
    "format binary_big_endian 1.0\n",
    "end_header\n",
    "255",
    "-1",
    "4294967295",
    "nan",
    "1e30",
    "\u{ff}\u{ff}\u{ff}\u{7f}",
    "\0\0\0\0",
];

/// Parses and builds one mesh (`parse` reads it); the peak bytes it took
/// and whether it became geometry.
fn mesh_case<E: std::fmt::Display>(
    parse: impl Fn() -> Result<trilux_geometry::TriangleMesh, E>,
) -> (usize, bool) {
    let base = reset_peak();
    let built = match parse() {
        Ok(mesh) => {
            let shape = Shape {
                kind: ShapeKind::Mesh(mesh),
                world_from_object: DMat4::IDENTITY,
                flip_normals: false,
            };
            match Geometry::build(&[shape]) {
                Ok(g) => g.primitive_count() > 0,
                Err(e) => {
                    assert!(!e.to_string().contains('\n'), "{e}");
                    false
                }
            }
        }
        Err(e) => {
            assert!(!e.to_string().contains('\n'), "{e}");
            false
        }
    };
    (peak() - base, built)
}

/// The OBJ loop; how many cases became geometry.
fn fuzz_obj(rng: &mut Rng) -> usize {
    let mut built = 0;
    for case in 0..OBJ_CASES {
        let mut bytes = SEEDS[case % SEEDS.len()].as_bytes().to_vec();
        for _ in 0..1 + rng.below(3) {
            mutate_text(rng, &mut bytes, &TOKENS);
        }
        let face_normals = rng.below(2) == 0;
        let (used, ok) = mesh_case(|| parse_obj(&bytes, Path::new("fuzz.obj"), face_normals, true));
        let bound = (256 << 10) + 256 * bytes.len();
        assert!(
            used <= bound,
            "OBJ case {case}: {used} bytes, bound {bound}: {:?}",
            String::from_utf8_lossy(&bytes)
        );
        built += usize::from(ok);
    }
    built
}

/// The PLY loop; how many cases became geometry.
fn fuzz_ply(rng: &mut Rng) -> usize {
    let mut built = 0;
    for case in 0..PLY_CASES {
        let mut bytes = PLY_SEEDS[case % PLY_SEEDS.len()].to_vec();
        for _ in 0..1 + rng.below(3) {
            mutate_text(rng, &mut bytes, &PLY_TOKENS);
        }
        let face_normals = rng.below(2) == 0;
        let (used, ok) =
            mesh_case(|| parse_ply(&bytes, Path::new("fuzz.ply"), face_normals, false));
        let bound = (256 << 10) + 256 * bytes.len();
        assert!(
            used <= bound,
            "PLY case {case}: {used} bytes, bound {bound}: {:?}",
            String::from_utf8_lossy(&bytes)
        );
        built += usize::from(ok);
    }
    built
}

/// A mesh stream of a serialized file: a pyramid of four triangles with
/// the parts `flags` asks for (0x1 normals, 0x2 texture coordinates, 0x8
/// colours, 0x2000 doubles), a name when `version` is 4.
fn serialized_stream(version: u16, flags: u32) -> Vec<u8> {
    let p = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.5, 0.5, 0.7],
    ];
    let mut d = flags.to_le_bytes().to_vec();
    if version == 4 {
        d.extend(b"pyramid\0");
    }
    d.extend(5u64.to_le_bytes());
    d.extend(4u64.to_le_bytes());
    let parts = [(0, 3), (0x1, 3), (0x2, 2), (0x8, 3)];
    for (flag, n) in parts {
        if flag == 0 || flags & flag != 0 {
            for v in &p {
                for &x in &v[..n] {
                    if flags & 0x2000 != 0 {
                        d.extend(f64::to_le_bytes(x));
                    } else {
                        d.extend((x as f32).to_le_bytes());
                    }
                }
            }
        }
    }
    for i in [0u32, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4] {
        d.extend(i.to_le_bytes());
    }
    d
}

/// A one-mesh file of `stream`, with its dictionary.
fn serialized_file(version: u16, stream: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(stream).unwrap();
    let mut out = 0x041Cu16.to_le_bytes().to_vec();
    out.extend(version.to_le_bytes());
    out.extend(z.finish().unwrap());
    if version == 4 {
        out.extend(0u64.to_le_bytes());
    } else {
        out.extend(0u32.to_le_bytes());
    }
    out.extend(1u32.to_le_bytes());
    out
}

/// One random change of binary `b`: a byte, a 64-bit count written over
/// any 8 bytes (extreme or at the limits), a cut, or a repeated range.
fn mutate_binary(rng: &mut Rng, b: &mut Vec<u8>) {
    if b.is_empty() {
        return;
    }
    let at = rng.below(b.len());
    match rng.below(4) {
        0 => b[at] = rng.next() as u8,
        1 => {
            let counts = [u64::MAX, 1 << 40, 12_000_000, 4_000_001, 0, 6, 1 << 32];
            let v = counts[rng.below(counts.len())].to_le_bytes();
            let end = (at + 8).min(b.len());
            b[at..end].copy_from_slice(&v[..end - at]);
        }
        2 => b.truncate(at),
        _ => {
            let end = (at + 1 + rng.below(64)).min(b.len());
            let piece = b[at..end].to_vec();
            b.splice(at..at, piece);
        }
    }
}

/// The serialized loop; how many cases became geometry.
fn fuzz_serialized(rng: &mut Rng) -> usize {
    let mut built = 0;
    for case in 0..SERIALIZED_CASES {
        let version = [3, 4][case % 2];
        let flags = [0x1000, 0x100B, 0x2003, 0x2008][(case / 2) % 4];
        let mut stream = serialized_stream(version, flags);
        let compressed_too = rng.below(8) == 0;
        for _ in 0..1 + rng.below(3) {
            mutate_binary(rng, &mut stream);
        }
        let mut bytes = serialized_file(version, &stream);
        if compressed_too {
            mutate_binary(rng, &mut bytes);
        }
        let face_normals = rng.below(2) == 0;
        let path = Path::new("fuzz.serialized");
        let (used, ok) = mesh_case(|| parse_serialized(&bytes, path, 0, face_normals));
        let bound = (256 << 10) + 256 * stream.len().max(bytes.len());
        assert!(
            used <= bound,
            "serialized case {case}: {used} bytes, bound {bound}: {stream:?}"
        );
        built += usize::from(ok);
    }
    built
}

const SCENE: &str = include_str!("../../../scenes/cornell-box.xml");

/// Pieces a mutation inserts into a scene: markup, references, defaults.
const XML_TOKENS: [&str; 16] = [
    "<",
    ">",
    "/>",
    "\"",
    "=",
    "$spp",
    "$res",
    "<ref id=\"white\"/>",
    "<shape type=\"cube\">",
    "</shape>",
    "<default name=\"spp\" value=\"$res$res\"/>",
    "1e30",
    "-1",
    "nan",
    "&amp;",
    "\u{feff}",
];

/// The scene loop; how many cases loaded.
fn fuzz_xml(rng: &mut Rng) -> usize {
    let mut loaded = 0;
    for case in 0..XML_CASES {
        let mut bytes = SCENE.as_bytes().to_vec();
        for _ in 0..1 + rng.below(3) {
            mutate_text(rng, &mut bytes, &XML_TOKENS);
        }
        let text = String::from_utf8_lossy(&bytes);
        let base = reset_peak();
        match trilux_scene::load_str(&text, "mutated.xml") {
            Ok(_) => loaded += 1,
            Err(e) => {
                // Each error one located line (a mutation can break
                // several independent elements).
                for one in e.errors() {
                    let msg = one.to_string();
                    assert!(
                        msg.starts_with("mutated.xml:") && !msg.contains('\n'),
                        "case {case}: {msg}"
                    );
                }
            }
        }
        let used = peak() - base;
        let bound = (1 << 20) + 64 * bytes.len();
        assert!(
            used <= bound,
            "scene case {case}: {used} bytes, bound {bound}"
        );
    }
    loaded
}

#[test]
fn mutated_meshes_and_scenes_never_panic_nor_exceed_their_memory_bounds() {
    let mut rng = Rng(14);
    // The seeds themselves build.
    for seed in SEEDS {
        let mesh = parse_obj(seed.as_bytes(), Path::new("seed.obj"), false, true);
        assert!(mesh.is_ok(), "{seed}: {:?}", mesh.err());
    }
    for seed in PLY_SEEDS {
        let mesh = parse_ply(seed, Path::new("seed.ply"), false, false);
        assert!(mesh.is_ok(), "{:?}", mesh.err());
    }
    for (version, flags) in [(3, 0x1000), (4, 0x100B), (4, 0x2003), (3, 0x2008)] {
        let bytes = serialized_file(version, &serialized_stream(version, flags));
        let mesh = parse_serialized(&bytes, Path::new("seed.serialized"), 0, false);
        assert!(mesh.is_ok(), "{:?}", mesh.err());
    }
    let built = fuzz_obj(&mut rng);
    let built_ply = fuzz_ply(&mut rng);
    let built_serialized = fuzz_serialized(&mut rng);
    let loaded = fuzz_xml(&mut rng);
    eprintln!(
        "{OBJ_CASES} OBJ cases ({built} built), {PLY_CASES} PLY cases ({built_ply} built), {XML_CASES} scene cases ({loaded} loaded)"
    );
    // Both kinds of outcome are exercised.
    assert!(built > OBJ_CASES / 10 && built < OBJ_CASES, "{built}");
    assert!(
        built_ply > PLY_CASES / 10 && built_ply < PLY_CASES,
        "{built_ply}"
    );
    assert!(loaded > XML_CASES / 10 && loaded < XML_CASES, "{loaded}");
    eprintln!("{SERIALIZED_CASES} serialized cases ({built_serialized} built)");
    assert!(
        built_serialized > SERIALIZED_CASES / 10 && built_serialized < SERIALIZED_CASES,
        "{built_serialized}"
    );
}
