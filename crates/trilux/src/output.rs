//! The command's outputs: every one named for what it is ([`named`]: the
//! format an image's name asks for, a bake's `.glb`, or a usage error,
//! status 2, before anything is read), planned and checked before any work
//! (`trilux_files::Output::plan`: folder, kind of file, symbolic links),
//! none equal to an input or to another, all written or none at the end
//! (`trilux_files::write_all`), and each one written reported on its own
//! line ([`Outputs::report`]).

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use trilux_files::{FileIdentity, Output};

/// A command-line mistake found once the arguments are parsed (an output
/// named for a format trilux does not write): one line `error: ...`, exit
/// status 2 as clap's usage errors, before any file is read (`main.rs`).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// What a command-line output is, and so which names it takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `render -o`: an EXR or a PNG, by the name's extension.
    Image,
    /// `render --png`: a PNG.
    Png,
    /// `solve -o`: a solution file (any name but an image's, a glTF
    /// file's or a JSON file's).
    Solution,
    /// `bake -o`: a glTF binary.
    Bake,
}

/// The format an output is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// OpenEXR, linear sRGB radiance.
    Exr,
    /// PNG, sRGB-encoded, exposed and clamped.
    Png,
    /// trilux's solution file.
    Solution,
    /// glTF 2.0 binary.
    Glb,
}

/// The format of `path`, an output of `kind` given with `option`, from
/// its extension (case aside): `.exr` and `.png` for an image, `.png`
/// for `--png`, `.glb` for a bake; a name without an extension (a device
/// such as `/dev/stdout`, a FIFO, a folder the planning then refuses) is
/// written in the kind's first format (EXR, PNG, solution, GLB). A name
/// that asks for another format (`-o out.jpg`, `--png x.exr`, a solution
/// named `.exr`) is a [`UsageError`]: trilux never writes one format under
/// another's name. The one check `render`, `solve` and `bake` share.
pub fn named(path: &Path, option: &str, kind: Kind) -> Result<Format, UsageError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let refuse = |why: &str| {
        UsageError(format!(
            "{option} {}: {why}",
            shown(&path.display().to_string())
        ))
    };
    let image = |e: &str| matches!(e, "exr" | "png" | "jpg" | "jpeg" | "tif" | "tiff" | "hdr");
    match (kind, ext.as_deref()) {
        (Kind::Image, None | Some("exr")) => Ok(Format::Exr),
        (Kind::Image | Kind::Png, Some("png")) | (Kind::Png, None) => Ok(Format::Png),
        (Kind::Image | Kind::Png, Some("jpg" | "jpeg")) => Err(refuse(
            "trilux writes no JPEG; name the image .exr (linear radiance) or .png (sRGB)",
        )),
        (Kind::Image, Some(_)) => Err(refuse(
            "an image is written as .exr (linear radiance) or .png (sRGB); name it so",
        )),
        (Kind::Png, Some(_)) => Err(refuse(
            "this option writes a PNG; name it .png (-o names the EXR)",
        )),
        (Kind::Solution, Some(e)) if image(e) || matches!(e, "glb" | "gltf" | "json") => Err(
            refuse("a solution file is not an image, a glTF file or JSON; name it .sol"),
        ),
        (Kind::Solution, _) => Ok(Format::Solution),
        (Kind::Bake, None | Some("glb")) => Ok(Format::Glb),
        (Kind::Bake, Some(_)) => Err(refuse("a bake is a glTF binary; name the output .glb")),
    }
}

/// `text` as it goes into a usage error, its middle elided when long.
fn shown(text: &str) -> String {
    trilux_scene::error::elide(text, 200)
}

/// The output a command writes when `-o` is not given:
/// `out/<scene's file stem>.<extension>` (the folder is made when
/// missing, only while planning and writing: [`Outputs::plan`]).
pub fn default_output(scene: &Path, extension: &str) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from("out").join(format!("{stem}.{extension}"))
}

/// The folder of default outputs.
pub const DEFAULT_FOLDER: &str = "out";

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

    /// Prints `wrote PATH` for every output, one line each, the first with
    /// `first_detail` after it (a bake's size): on stdout, or on stderr
    /// when an output is the standard output itself (`-o /dev/stdout`),
    /// so that the report never mixes with an output's bytes. Called once
    /// the files are written.
    pub fn report(&self, first_detail: Option<&str>) -> Result<()> {
        let mut text = String::new();
        for (k, out) in self.planned.iter().enumerate() {
            text.push_str(&format!("wrote {}", out.path().display()));
            if let (0, Some(detail)) = (k, first_detail) {
                text.push_str(&format!(" ({detail})"));
            }
            text.push('\n');
        }
        let stdout = FileIdentity::of(Path::new("/dev/stdout")).ok();
        if self
            .planned
            .iter()
            .any(|o| Some(o.identity()) == stdout.as_ref())
        {
            for line in text.lines() {
                crate::streams::eprint_line(line);
            }
            Ok(())
        } else {
            crate::streams::print(&text)
        }
    }
}

/// The statistics JSON: the solver's figures plus the render time, what
/// the render left out and the run's record.
pub fn stats_json(
    stats: &trilux_solver::SolveStats,
    render: Option<&trilux_render::RenderStats>,
    render_seconds: f64,
    record: &crate::record::Record,
) -> Result<Vec<u8>> {
    let mut value = serde_json::to_value(stats)?;
    if let Some(map) = value.as_object_mut() {
        map.insert("render_seconds".into(), serde_json::json!(render_seconds));
        map.insert("record".into(), serde_json::to_value(record)?);
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
/// (`bake`: bytes, vertices, triangles, seconds, max_flux_error,
/// glossy_vertices, glossy_seconds) and the
/// run's record.
pub fn bake_stats_json(
    stats: &trilux_solver::SolveStats,
    bake: &trilux_bake::BakeStats,
    record: &crate::record::Record,
) -> Result<Vec<u8>> {
    let mut value = serde_json::to_value(stats)?;
    if let Some(map) = value.as_object_mut() {
        map.insert("record".into(), serde_json::to_value(record)?);
        map.insert(
            "bake".into(),
            serde_json::json!({
                "bytes": bake.bytes,
                "vertices": bake.vertices,
                "triangles": bake.triangles,
                "seconds": bake.seconds,
                "max_flux_error": bake.max_flux_error,
                "glossy_vertices": bake.glossy_vertices,
                "glossy_seconds": bake.glossy_seconds,
            }),
        );
    }
    Ok(serde_json::to_vec_pretty(&value)?)
}
