//! A furnace of smooth plastic (Mitsuba's `plastic`), solved and rendered.
//!
//! Closed form: with specular_reflectance s and the diffuse reflectance d
//! chosen so that ρ'T̄/η² = s (ρ' = d/(1 − F_dr), T̄ = 2∫(1 − F(μ))μ dμ),
//! the plastic's directional albedo is F(θ)·s + (1 − F(θ))·s = s at every
//! angle (the mirror reflects F, the base returns ρ'T(θ)T̄/η² = sT(θ)).
//! Inside a closed cube whose faces emit 1, the radiance is then uniform
//! and exactly 1/(1 − s) = 2 for s = ½, in Mitsuba as in trilux. The
//! solve carries the mirror's energy in its Lambertian part
//! (trilux_brdf::plastic): a wrong share (the mirror dropped, or counted
//! twice) moves the mean by 5–10 %. Criterion as the diffuse furnace's:
//! mean within 0.5 %, 99 % of pixels within 2 %.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use trilux::{Observer, Plan, RenderPlan, SolutionSource, ViewOverrides};
use trilux_render::{Estimator, RenderSettings};
use trilux_solver::{Quality, SolverSettings};

/// Unpolarised Fresnel reflectance of a dielectric of index `eta` seen from
/// outside (the textbook s and p amplitudes).
fn fresnel(c: f64, eta: f64) -> f64 {
    let ct = (1.0 - (1.0 - c * c) / (eta * eta)).max(0.0).sqrt();
    let rs = (c - eta * ct) / (c + eta * ct);
    let rp = (ct - eta * c) / (ct + eta * c);
    0.5 * (rs * rs + rp * rp)
}

/// The diffuse reflectance that makes the albedo uniform (module docs), for
/// Mitsuba's default indices; F_dr is Mitsuba's fit (Egan & Hilgeman, for
/// the internal side, 1/η).
fn uniform_diffuse(s: f64) -> f64 {
    let eta = 1.49 / 1.000277;
    let n = 100_000;
    let t_mean: f64 = (0..n)
        .map(|i| {
            let mu = (i as f64 + 0.5) / n as f64;
            2.0 * (1.0 - fresnel(mu, eta)) * mu / n as f64
        })
        .sum();
    let e = 1.0 / eta;
    let fdr = 0.0636 / e + e * (e * -1.4399 + 0.7099) + 0.6681;
    s * eta * eta * (1.0 - fdr) / t_mean
}

#[test]
fn smooth_plastic_furnace_renders_two() {
    let d = uniform_diffuse(0.5);
    let xml = format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world"><lookat origin="0, 0, 0.5" target="0, 0, -1" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="64"/></film>
    </sensor>
    <shape type="cube">
        <boolean name="flip_normals" value="true"/>
        <bsdf type="plastic">
            <float name="diffuse_reflectance" value="{d}"/>
            <float name="specular_reflectance" value="0.5"/>
        </bsdf>
        <emitter type="area"><float name="radiance" value="1.0"/></emitter>
    </shape>
</scene>"#
    );
    let dir = std::env::temp_dir().join(format!("trilux-plastic-furnace-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("plastic-furnace.xml");
    std::fs::write(&path, xml).unwrap();
    let scene = trilux_scene::load(&path).unwrap();
    let settings = RenderSettings {
        spp: 64,
        estimator: Estimator::Links,
        ..trilux::render_settings(scene.camera.as_ref().unwrap())
    };
    let plan = Plan {
        mode: scene.mode(),
        solver: SolverSettings::preset(Quality::Default),
        source: SolutionSource::Solve,
        save: None,
        solution_file: false,
        bake: None,
        render: Some(RenderPlan {
            view: ViewOverrides::default(),
            settings,
        }),
    };
    let outcome = Observer::quiet(|o| trilux::pipeline::run(&scene, &plan, o)).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert!(outcome.solve.convergence_ratio >= 0.99);
    let img = outcome.image.unwrap();
    let within = img
        .pixels()
        .iter()
        .filter(|p| p.iter().all(|&c| (c - 2.0).abs() <= 0.02 * 2.0))
        .count() as f64
        / img.pixels().len() as f64;
    println!(
        "d = {d}: mean {:?}, {within:.4} of pixels within 2 %",
        img.mean()
    );
    for m in img.mean() {
        assert!((m - 2.0).abs() <= 0.005 * 2.0, "mean {:?}", img.mean());
    }
    assert!(within >= 0.99, "only {within} of pixels within 2 %");
}
