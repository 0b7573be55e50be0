//! The command's outputs: every one planned and checked before any work
//! (`trilux_files::Output::plan`: folder, kind of file, symbolic links),
//! none equal to an input or to another, and all written or none at the
//! end (`trilux_files::write_all`).

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use trilux_files::{FileIdentity, Output};

/// The outputs of one command, in the order given to [`Outputs::plan`].
pub struct Outputs {
    planned: Vec<Output>,
    /// The default folder (`out/`) when it did not exist: made to plan
    /// the outputs in it and removed at once, made again only to write
    /// them (so a command killed during its work, by SIGINT or SIGTERM,
    /// which runs no destructor, leaves no empty folder behind), and
    /// removed again if it is still empty when the command ends.
    made: Option<PathBuf>,
}

impl Drop for Outputs {
    fn drop(&mut self) {
        if let Some(dir) = &self.made {
            // Fails, as it should, once the folder holds the outputs.
            let _ = std::fs::remove_dir(dir);
        }
    }
}

impl Outputs {
    /// Plans `outputs` (path and what it is) of a command reading
    /// `inputs`. `default_folder` is the folder of outputs the user did not
    /// name: when missing, made only while planning and while writing
    /// (`made`).
    pub fn plan(
        outputs: &[(&Path, &str)],
        inputs: &[&Path],
        default_folder: Option<&Path>,
    ) -> Result<Outputs> {
        let mut made = None;
        if let Some(dir) = default_folder
            && !dir.exists()
        {
            std::fs::create_dir_all(dir)
                .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
            made = Some(dir.to_path_buf());
        }
        let mut planned = Outputs {
            planned: Vec::new(),
            made,
        };
        for (path, what) in outputs {
            planned.planned.push(Output::plan(path, what)?);
        }
        planned.check_distinct(inputs)?;
        if let Some(dir) = &planned.made {
            // Planned (identities taken while it existed): nothing is in it.
            let _ = std::fs::remove_dir(dir);
        }
        Ok(planned)
    }

    /// Refuses an output that is an input, or the same file as another
    /// output (two outputs written through to one device are allowed:
    /// nothing is overwritten).
    fn check_distinct(&self, inputs: &[&Path]) -> Result<()> {
        // An input that cannot be identified (missing) is reported by the
        // loader, with its own message.
        let inputs: Vec<(&Path, FileIdentity)> = inputs
            .iter()
            .filter_map(|p| FileIdentity::of(p).ok().map(|id| (*p, id)))
            .collect();
        for (k, out) in self.planned.iter().enumerate() {
            if let Some((input, _)) = inputs.iter().find(|(_, id)| id == out.identity()) {
                bail!(
                    "{}: the {} would overwrite the input {}",
                    out.path().display(),
                    out.what(),
                    input.display()
                );
            }
            let same = |o: &&Output| o.identity() == out.identity();
            if let Some(other) = self.planned[..k].iter().find(same)
                && !(other.is_write_through() && out.is_write_through())
            {
                bail!(
                    "{}: the {} and the {} are the same file",
                    out.path().display(),
                    out.what(),
                    other.what()
                );
            }
        }
        Ok(())
    }

    /// Refuses an output that is one of the files the scene reads
    /// (`trilux_scene::Pending::input_files`: meshes, textures, glTF
    /// buffers, included files), compared as files (symbolic and hard
    /// links seen through); called once the scene is opened, before any
    /// of the work.
    pub fn check_inputs(&self, inputs: &[PathBuf]) -> Result<()> {
        for input in inputs {
            let Ok(id) = FileIdentity::of(input) else {
                continue; // missing: the loader says so
            };
            if let Some(out) = self.planned.iter().find(|o| *o.identity() == id) {
                bail!(
                    "{}: the {} would overwrite the input {}",
                    out.path().display(),
                    out.what(),
                    input.display()
                );
            }
        }
        Ok(())
    }

    /// Writes every output, `bytes` in the planned order, or none.
    pub fn write(&self, bytes: &[Vec<u8>]) -> Result<()> {
        if bytes.len() != self.planned.len() {
            bail!(
                "{} outputs planned, {} produced",
                self.planned.len(),
                bytes.len()
            );
        }
        if let Some(dir) = &self.made {
            std::fs::create_dir_all(dir)
                .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
        }
        let items: Vec<(&Output, &[u8])> = self
            .planned
            .iter()
            .zip(bytes)
            .map(|(o, b)| (o, b.as_slice()))
            .collect();
        trilux_files::write_all(&items)?;
        Ok(())
    }
}

/// The statistics JSON: the solver's figures plus the render time and
/// what the render left out.
pub fn stats_json(
    stats: &trilux_solver::SolveStats,
    render: Option<&trilux_render::RenderStats>,
    render_seconds: f64,
) -> Result<Vec<u8>> {
    let mut value = serde_json::to_value(stats)?;
    if let Some(map) = value.as_object_mut() {
        map.insert("render_seconds".into(), serde_json::json!(render_seconds));
        if let Some(r) = render {
            map.insert(
                "dropped_samples".into(),
                serde_json::json!(r.gather.dropped),
            );
            map.insert(
                "camera_samples".into(),
                serde_json::json!(r.gather.camera_rays),
            );
        }
    }
    Ok(serde_json::to_vec_pretty(&value)?)
}

/// The statistics JSON of a bake: the solver's figures plus the file's
/// (`bake`: bytes, vertices, triangles, seconds, max_flux_error).
pub fn bake_stats_json(
    stats: &trilux_solver::SolveStats,
    bake: &trilux_bake::BakeStats,
) -> Result<Vec<u8>> {
    let mut value = serde_json::to_value(stats)?;
    if let Some(map) = value.as_object_mut() {
        map.insert(
            "bake".into(),
            serde_json::json!({
                "bytes": bake.bytes,
                "vertices": bake.vertices,
                "triangles": bake.triangles,
                "seconds": bake.seconds,
                "max_flux_error": bake.max_flux_error,
            }),
        );
    }
    Ok(serde_json::to_vec_pretty(&value)?)
}
