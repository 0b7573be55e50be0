//! The ambient term (docs/solver.md, "Convergence ratio and ambient
//! term") on a small closed room stopped early: the image mean with the
//! term is closer to the converged image's mean than without it, and within
//! 5 % of it. The reference is the same scene solved to CR 0.9999 and
//! rendered the same way (the preview estimator: no noise to compare
//! through).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test, bench or example may panic

use trilux::{ViewOverrides, prepare, scene_camera};
use trilux_render::{Estimator, RenderSettings, render};
use trilux_solver::{Quality, Solution, Solver, SolverSettings};

/// A closed white room (2 m cube seen from inside, ρ 0.7) with a lamp under
/// the ceiling and a grey box on the floor; the camera inside.
const ROOM: &str = r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="70"/>
        <transform name="to_world">
            <lookat origin="0.2, 0.1, 0.9" target="-0.2, -0.3, -1" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="32"/>
            <integer name="height" value="32"/>
        </film>
    </sensor>
    <shape type="cube">
        <boolean name="flip_normals" value="true"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.75, 0.7, 0.6"/></bsdf>
    </shape>
    <shape type="cube">
        <transform name="to_world">
            <scale x="0.3" y="0.4" z="0.3"/>
            <translate x="-0.3" y="-0.6" z="-0.2"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale x="0.25" y="0.25" z="0.25"/>
            <rotate x="1" angle="90"/>
            <translate y="0.99"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="20"/></emitter>
    </shape>
</scene>"#;

fn solve(convergence: f64) -> Solution<3> {
    let scene = trilux_scene::load_str(ROOM, "room.xml").unwrap();
    let mut settings = SolverSettings::preset(Quality::Draft);
    settings.convergence = convergence;
    Solver::new(prepare::<3>(&scene).unwrap(), settings)
        .unwrap()
        .solve(|_| {})
}

fn mean(solution: &Solution<3>) -> f64 {
    let scene = trilux_scene::load_str(ROOM, "room.xml").unwrap();
    let camera = scene_camera(&scene, &ViewOverrides::default()).unwrap();
    let settings = RenderSettings {
        spp: 1,
        estimator: Estimator::Preview,
        ..trilux::render_settings(scene.camera.as_ref().unwrap())
    };
    let (img, _) = render(solution, &camera, &settings, |_, _| {}).unwrap();
    img.mean().iter().sum::<f64>() / 3.0
}

#[test]
fn an_early_stop_with_the_ambient_term_is_within_five_percent_of_the_converged_mean() {
    let converged = solve(0.9999);
    assert!(converged.stats().convergence_ratio >= 0.9999);
    let reference = mean(&converged);
    let mut stopped = solve(0.6);
    let cr = stopped.stats().convergence_ratio;
    assert!(cr < 0.8, "the solve did not stop early: CR {cr}");
    let with = mean(&stopped);
    stopped.set_ambient(false);
    let without = mean(&stopped);
    let (e_with, e_without) = (with / reference - 1.0, without / reference - 1.0);
    println!("stopped at CR {cr}: with the term {e_with:+.4}, without {e_without:+.4}");
    assert!(
        e_without < -0.05,
        "stopped at CR {cr} the room should be visibly dark without the term: {e_without:+.4}"
    );
    assert!(
        e_with.abs() < e_without.abs(),
        "with the term {e_with:+.4}, without {e_without:+.4}"
    );
    assert!(
        e_with.abs() <= 0.05,
        "with the term the mean is {e_with:+.4} off the converged one (CR {cr})"
    );
}
