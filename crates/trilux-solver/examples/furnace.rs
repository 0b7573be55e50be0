//! Solves the furnace (a closed diffuse box that emits everywhere) and
//! prints the radiance at a few points and the energy ledger.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use glam::{DMat4, DVec2};
use trilux_brdf::BsdfParams;
use trilux_color::ColorParam;
use trilux_geometry::{Shape, ShapeKind, Side, SurfaceCoord, SurfaceId};
use trilux_solver::{Quality, SceneDescription, Solver, SolverSettings, SurfaceSite};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let shapes = vec![Shape {
        kind: ShapeKind::Cube,
        world_from_object: DMat4::IDENTITY,
        flip_normals: true,
    }];
    let bsdfs = vec![BsdfParams::Diffuse {
        reflectance: ColorParam::Float(0.5),
    }];
    let emission = vec![Some(ColorParam::Float(1.0))];
    let input = SceneDescription {
        shapes: &shapes,
        bsdfs: &bsdfs,
        emission: &emission,
    };
    let mut settings = SolverSettings::preset(Quality::Default);
    settings.convergence = 0.999;
    settings.max_depth = 3;
    let solution = Solver::<3>::from_description(&input, settings)?.solve(|p| {
        if p.shots % 10 == 0 {
            println!(
                "shot {:4}  CR {:.5}  links {}",
                p.shots, p.convergence_ratio, p.live_links
            );
        }
    });
    for f in 0..6u32 {
        let mut row = String::new();
        for a in 0..5 {
            let uv = DVec2::new((a as f64 + 0.5) / 5.0, 0.5);
            let site = SurfaceSite::new(SurfaceId(f), Side::Front, SurfaceCoord::Uv(uv));
            row += &format!(" {:.4}", solution.lambertian_radiance(&site)[0] + 1.0);
        }
        println!("face {f}:{row}");
    }
    println!("{}", serde_json::to_string_pretty(solution.stats())?);
    Ok(())
}
