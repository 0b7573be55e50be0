//! The record of a run: what made its outputs and how the run went
//! (trilux's version, the command line, every setting, the seconds of each
//! phase, the peak resident memory, the solve's convergence trace), so that
//! runs can be compared later. Written as the `record` key of `--stats`
//! JSON and as string attributes of a rendered EXR's header
//! (docs/architecture.md, "The record").

mod memory;
mod settings;

use std::sync::OnceLock;
use std::time::Instant;

use anyhow::Result;
use serde::Serialize;
use serde_json::{Map, Value};
use trilux_solver::TracePoint;

pub use memory::peak_resident_bytes;

/// When the command started (`main`'s first step, [`start`]).
static START: OnceLock<Instant> = OnceLock::new();

/// Marks the command's start: the phases and the wall time count from it.
pub fn start() {
    START.get_or_init(Instant::now);
}

/// Seconds since [`start`].
pub fn elapsed() -> f64 {
    START.get_or_init(Instant::now).elapsed().as_secs_f64()
}

/// How a run went and what steered it (module docs).
#[derive(Clone, Debug, Serialize)]
pub struct Record {
    /// The version of the `trilux` that ran.
    pub trilux_version: &'static str,
    /// The command line, program name first (lossy UTF-8).
    pub command_line: Vec<String>,
    /// Every setting of the run, those left at their defaults included.
    pub settings: Map<String, Value>,
    /// Where the time went.
    pub phases: Phases,
    /// The process's peak resident memory (Linux's VmHWM; `None`
    /// elsewhere).
    pub peak_resident_bytes: Option<u64>,
    /// The solve's convergence (`SolveStats::convergence_trace`; a loaded
    /// solution's is that of the solve that made it, kept in its file).
    pub convergence_trace: Vec<TracePoint>,
}

/// Wall-clock seconds of each phase of a run, and of the whole run.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Phases {
    /// From the command's start to the start of the work: the arguments,
    /// the outputs' planning, the scene file with its meshes and textures.
    pub read_seconds: f64,
    /// The scene prepared for the solver (geometry, BVH, materials).
    pub prepare_seconds: f64,
    /// The solve, or the loading of a saved solution.
    pub solve_seconds: f64,
    /// The bake (0 unless `bake`).
    pub bake_seconds: f64,
    /// The render (0 unless `render`).
    pub render_seconds: f64,
    /// From the command's start to the end of the work (the outputs are
    /// encoded and written after): at least the sum of the phases.
    pub wall_seconds: f64,
}

impl Record {
    /// The record of `plan` carried out on `scene` with `outcome`, its
    /// work begun `read_seconds` after the command's start.
    pub fn new(
        scene: &trilux_scene::Scene,
        plan: &trilux::Plan<'_>,
        outcome: &trilux::Outcome,
        read_seconds: f64,
    ) -> Result<Record> {
        let phases = Phases {
            read_seconds,
            prepare_seconds: outcome.prepare_seconds,
            solve_seconds: outcome.solve_seconds,
            bake_seconds: outcome.baked.as_ref().map_or(0.0, |b| b.stats.seconds),
            render_seconds: match outcome.render {
                Some(_) => outcome.render_seconds,
                None => 0.0,
            },
            wall_seconds: elapsed(),
        };
        Ok(Record {
            trilux_version: env!("CARGO_PKG_VERSION"),
            command_line: std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
            settings: settings::of_plan(scene, plan)?,
            phases,
            peak_resident_bytes: peak_resident_bytes(),
            convergence_trace: outcome.solve.convergence_trace.clone(),
        })
    }

    /// Adds a setting the plan does not hold (a command's own, such as
    /// the PNG's exposure).
    pub fn set(&mut self, name: &str, value: Value) {
        self.settings.insert(name.into(), value);
    }

    /// The record as EXR header attributes (name, text): `software` (the
    /// standard attribute) and one `trilux.*` attribute per key, each
    /// value JSON with every character beyond ASCII escaped (the header's
    /// strings are bytes; OpenEXR tools show them as they are).
    pub fn exr_attributes(&self) -> Result<Vec<(&'static str, String)>> {
        let json = |v: Value| ascii(&v.to_string());
        Ok(vec![
            ("software", format!("trilux {}", self.trilux_version)),
            ("trilux.version", self.trilux_version.to_string()),
            (
                "trilux.commandLine",
                json(serde_json::to_value(&self.command_line)?),
            ),
            (
                "trilux.settings",
                json(Value::Object(self.settings.clone())),
            ),
            ("trilux.phases", json(serde_json::to_value(self.phases)?)),
            (
                "trilux.peakResidentBytes",
                json(serde_json::to_value(self.peak_resident_bytes)?),
            ),
            (
                "trilux.convergenceTrace",
                json(serde_json::to_value(&self.convergence_trace)?),
            ),
        ])
    }
}

/// JSON text with every character beyond ASCII written as `\uXXXX`
/// (UTF-16 code units): the same JSON value, in bytes any header takes.
/// Such characters occur only inside strings, where the escape is valid.
fn ascii(json: &str) -> String {
    let mut out = String::with_capacity(json.len());
    for c in json.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            let mut units = [0u16; 2];
            for u in c.encode_utf16(&mut units) {
                out.push_str(&format!("\\u{u:04x}"));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaped_json_reads_back_as_the_same_value() {
        let value = serde_json::json!(["plain", "é", "日本", "🙂", "\"q\""]);
        let text = ascii(&value.to_string());
        assert!(text.is_ascii());
        let back: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, value);
    }
}
