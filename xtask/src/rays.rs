//! `cargo xtask rays [--rays N] [--no-mitsuba]`: ray-query throughput of
//! trilux against Embree (inside Mitsuba 3's `llvm_ad_rgb` variant), on the
//! same triangles and the same rays, on 1 and 2 threads.
//!
//! Scenes: the ray benchmark's ~100k-triangle UV sphere in a box (rays
//! from random points in the box in random directions, segments between
//! random pairs of such points), its Cornell box and the bundled
//! `paper-scene3` (gather-like rays from points on the surfaces into their
//! front hemisphere, segments between points on two random surfaces);
//! 4 M rays and 4 M segments each (`crates/trilux-geometry/benches/scenes`
//! makes them). trilux traces them with `Geometry::intersect_batch` and
//! `Geometry::occluded_batch` (closest hits with their surface, coordinates
//! and normals) in chunks of 65 536; Mitsuba traces them from Python
//! (`xtask/rays_mitsuba.py`, rays passed through `target/rays/rays.bin`)
//! with `ray_intersect_preliminary` and `ray_test`. Every figure is the best
//! of three runs after an untimed one; run it on an otherwise idle machine.
//!
//! Prints a Markdown table of Mrays/s and a last line `trilux/embree
//! closest R1 shadow R2`: the two ratios on 2 threads on the 100k scene.
//! A debug build (`cargo xtask` is one) runs the release build instead.

#[allow(clippy::unwrap_used, clippy::expect_used)]
#[path = "../../crates/trilux-geometry/benches/scenes/mod.rs"]
mod scenes;

use std::hint::black_box;
use std::io::Write;
use std::process::Command;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::DVec3;
use trilux_geometry::{ElementForest, Geometry, Ray};

use crate::golden::root;

const CHUNK: usize = 1 << 16;
const REPS: usize = 3;
const THREADS: [usize; 2] = [1, 2];

/// One scene and its workload.
struct Case {
    name: &'static str,
    geom: Arc<Geometry>,
    rays: Vec<Ray>,
    segs: Vec<(DVec3, DVec3)>,
}

/// Seconds and result counts of one scene on one thread count.
#[derive(Clone, Copy, Debug, Default)]
struct Timing {
    closest: f64,
    shadow: f64,
    hits: usize,
    occluded: usize,
}

pub fn main(args: &[String]) -> Result<()> {
    // `cargo xtask` builds the debug profile: time optimised code only.
    if cfg!(debug_assertions) {
        let mut release = vec!["run", "--release", "--quiet", "-p", "xtask", "--", "rays"];
        release.extend(args.iter().map(String::as_str));
        return crate::run("cargo", &release);
    }
    let mut count = 4_000_000usize;
    let mut with_mitsuba = true;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--rays" => count = it.next().context("--rays N")?.parse()?,
            "--no-mitsuba" => with_mitsuba = false,
            other => bail!("unknown argument {other}"),
        }
    }
    let cases = cases(count)?;
    let ours: Vec<Vec<Timing>> = cases
        .iter()
        .map(|c| THREADS.iter().map(|&t| trace(c, t)).collect())
        .collect::<Result<_>>()?;
    let embree = if with_mitsuba && mitsuba_available() {
        let file = root().join("target/rays/rays.bin");
        write_rays(&file, &cases)?;
        Some(mitsuba(&file, &cases)?)
    } else {
        eprintln!("rays: Mitsuba 3 not found (python3 -c 'import mitsuba'): trilux only");
        None
    };
    print_table(&cases, &ours, embree.as_deref());
    Ok(())
}

/// The three scenes with `count` rays and segments each.
fn cases(count: usize) -> Result<Vec<Case>> {
    let sphere = Geometry::build_shared(&scenes::sphere_in_box(160))?;
    let (rays, segs) = scenes::workload(&sphere, count, 1);
    let mut out = vec![Case {
        name: "sphere_in_box_102k",
        geom: sphere,
        rays,
        segs,
    }];
    let scene3 = trilux_scene::load(root().join("scenes/paper-scene3.xml"))?;
    for (name, shapes, seed) in [
        ("cornell_box", scenes::cornell_box(), 2),
        ("paper-scene3", scene3.geometry_shapes(), 3),
    ] {
        let geom = Geometry::build_shared(&shapes)?;
        let forest = ElementForest::new(Arc::clone(&geom));
        let (rays, segs) = scenes::surface_workload(&forest, count, seed);
        out.push(Case {
            name,
            geom,
            rays,
            segs,
        });
    }
    Ok(out)
}

/// Best of [`REPS`] runs of `f` after an untimed one, and its result.
fn best_of(f: impl Fn() -> usize) -> (f64, usize) {
    let mut result = f();
    let mut best = f64::INFINITY;
    for _ in 0..REPS {
        let t0 = Instant::now();
        result = black_box(f());
        best = best.min(t0.elapsed().as_secs_f64());
    }
    (best, result)
}

/// trilux's timings of one case on `threads` threads.
fn trace(c: &Case, threads: usize) -> Result<Timing> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let g = &c.geom;
    let (closest, hits) = best_of(|| {
        pool.install(|| {
            c.rays
                .chunks(CHUNK)
                .map(|r| g.intersect_batch(r, f64::INFINITY).iter().flatten().count())
                .sum()
        })
    });
    let (shadow, occluded) = best_of(|| {
        pool.install(|| {
            c.segs
                .chunks(CHUNK)
                .map(|s| g.occluded_batch(s).iter().filter(|&&o| o).count())
                .sum()
        })
    });
    Ok(Timing {
        closest,
        shadow,
        hits,
        occluded,
    })
}

fn mitsuba_available() -> bool {
    Command::new("python3")
        .args(["-c", "import mitsuba"])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The triangles, rays and segments of every case, in the format
/// `xtask/rays_mitsuba.py` reads (its docstring).
fn write_rays(path: &std::path::Path, cases: &[Case]) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    let u32le = |w: &mut dyn Write, v: usize| w.write_all(&(v as u32).to_le_bytes());
    let f32s = |w: &mut dyn Write, v: &[DVec3]| -> std::io::Result<()> {
        for p in v {
            for c in p.as_vec3().to_array() {
                w.write_all(&c.to_le_bytes())?;
            }
        }
        Ok(())
    };
    w.write_all(b"TLXRAYS1")?;
    u32le(&mut w, cases.len())?;
    for c in cases {
        u32le(&mut w, c.name.len())?;
        w.write_all(c.name.as_bytes())?;
        let tris = c.geom.primitive_triangles();
        u32le(&mut w, tris.len())?;
        for t in &tris {
            f32s(&mut w, t)?;
        }
        u32le(&mut w, c.rays.len())?;
        for r in &c.rays {
            f32s(&mut w, &[r.origin, r.dir])?;
        }
        u32le(&mut w, c.segs.len())?;
        for &(p, q) in &c.segs {
            f32s(&mut w, &[p, q])?;
        }
    }
    w.flush()?;
    Ok(())
}

/// Embree's timings, per case and thread count.
fn mitsuba(file: &std::path::Path, cases: &[Case]) -> Result<Vec<Vec<Timing>>> {
    let o = Command::new("python3")
        .arg(root().join("xtask/rays_mitsuba.py"))
        .arg(file)
        .args(THREADS.map(|t| t.to_string()))
        .output()
        .context("starting python3")?;
    if !o.status.success() {
        bail!(
            "rays_mitsuba.py failed: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let mut out = vec![vec![Timing::default(); THREADS.len()]; cases.len()];
    let text = String::from_utf8_lossy(&o.stdout);
    for line in text.lines().filter(|l| l.starts_with('{')) {
        let v: serde_json::Value = serde_json::from_str(line)?;
        let scene = v["scene"].as_str().unwrap_or_default();
        let threads = v["threads"].as_u64().unwrap_or_default() as usize;
        let (Some(i), Some(j)) = (
            cases.iter().position(|c| c.name == scene),
            THREADS.iter().position(|&t| t == threads),
        ) else {
            bail!("rays_mitsuba.py printed an unknown case: {line}");
        };
        out[i][j] = Timing {
            closest: v["closest"].as_f64().unwrap_or(f64::NAN),
            shadow: v["shadow"].as_f64().unwrap_or(f64::NAN),
            hits: v["hits"].as_u64().unwrap_or_default() as usize,
            occluded: v["occluded"].as_u64().unwrap_or_default() as usize,
        };
    }
    Ok(out)
}

fn print_table(cases: &[Case], ours: &[Vec<Timing>], embree: Option<&[Vec<Timing>]>) {
    println!(
        "| scene | triangles | query | threads | trilux Mrays/s | Embree Mrays/s | trilux/Embree | results trilux / Embree |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mrays = |n: usize, s: f64| n as f64 / s / 1e6;
    let mut last = (f64::NAN, f64::NAN);
    for (i, c) in cases.iter().enumerate() {
        let tris = c.geom.primitive_triangles().len();
        for (j, &threads) in THREADS.iter().enumerate() {
            let t = ours[i][j];
            let e = embree.map(|e| e[i][j]);
            for (query, n, s, es, res, eres) in [
                (
                    "closest",
                    c.rays.len(),
                    t.closest,
                    e.map(|e| e.closest),
                    t.hits,
                    e.map(|e| e.hits),
                ),
                (
                    "shadow",
                    c.segs.len(),
                    t.shadow,
                    e.map(|e| e.shadow),
                    t.occluded,
                    e.map(|e| e.occluded),
                ),
            ] {
                let ours = mrays(n, s);
                let theirs = es.map(|es| mrays(n, es));
                let ratio = theirs.map(|th| ours / th);
                if i == 0 && threads == 2 {
                    let r = ratio.unwrap_or(f64::NAN);
                    if query == "closest" {
                        last.0 = r;
                    } else {
                        last.1 = r;
                    }
                }
                let opt = |x: Option<f64>, p: usize| {
                    x.map_or_else(|| "–".to_string(), |x| format!("{x:.p$}"))
                };
                println!(
                    "| {} | {tris} | {query} | {threads} | {ours:.2} | {} | {} | {res} / {} |",
                    c.name,
                    opt(theirs, 2),
                    opt(ratio, 2),
                    eres.map_or_else(|| "–".to_string(), |x| x.to_string()),
                );
            }
        }
    }
    let ratio = |r: f64| {
        if r.is_nan() {
            "n/a".to_string()
        } else {
            format!("{r:.2}")
        }
    };
    println!(
        "trilux/embree closest {} shadow {}",
        ratio(last.0),
        ratio(last.1)
    );
}
