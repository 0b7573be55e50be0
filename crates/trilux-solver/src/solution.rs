//! The solution: radiance leaving any point towards any other point, for
//! final gathering (paper §4.5), and its file format.

use std::collections::HashMap;
use std::io::{Read, Write};
use std::path::Path;

use trilux_color::Spectrum;
use trilux_geometry::{SceneGeometry, SurfaceCoord, SurfaceId};

use crate::error::SolverError;
use crate::interaction::{Hierarchy, NO_CHILD, Node, Split};
use crate::settings::SolverSettings;
use crate::solver::{Solver, SolverInput, presubdivide};
use crate::stats::SolveStats;

/// A view-independent solution of the scene's light.
pub struct Solution<const N: usize> {
    geom: SceneGeometry,
    settings: SolverSettings,
    depth_of: Vec<u32>,
    /// Exposed area of every element's faces, `[back][element]`
    /// (`trilux_geometry::burial`).
    exposed_area: [Vec<f64>; 2],
    /// Two-point (Lambertian) reflected radiance, `[back][element]`.
    radiance: [Vec<Spectrum<N>>; 2],
    hierarchies: Vec<Hierarchy<N>>,
    by_sides: HashMap<(u32, u32), u32>,
    stats: SolveStats,
}

/// One end of a radiance query: a point of an input surface and the face
/// of the surface the light leaves or arrives on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSite {
    /// The input surface.
    pub surface: SurfaceId,
    /// The point, in the surface's coordinates.
    pub coord: SurfaceCoord,
    /// True for the back face (against the geometric normal).
    pub back: bool,
}

impl<const N: usize> Solution<N> {
    pub(crate) fn from_solver(solver: Solver<N>) -> Self {
        let by_sides = solver
            .hierarchies
            .iter()
            .enumerate()
            .map(|(i, h)| ((h.from, h.to), i as u32))
            .collect();
        let mut stats = solver.stats;
        // The ledger's per-element and per-shot minima are diagnostics worth
        // keeping beside the stats.
        if solver.ledger.min_shot_escaped < -1e-9 {
            stats.warnings.push(format!(
                "a shot created energy: escaped flux {} of its source",
                solver.ledger.min_shot_escaped
            ));
        }
        Solution {
            geom: solver.geom,
            settings: solver.settings,
            depth_of: solver.depth_of,
            exposed_area: solver.exposed_area,
            radiance: solver.field.radiance,
            hierarchies: solver.hierarchies,
            by_sides,
            stats,
        }
    }

    /// Statistics of the solve that made this solution.
    pub fn stats(&self) -> &SolveStats {
        &self.stats
    }

    /// Mutable statistics (for the caller's timing of rendering).
    pub fn stats_mut(&mut self) -> &mut SolveStats {
        &mut self.stats
    }

    /// The geometry the solution refers to.
    pub fn geometry(&self) -> &SceneGeometry {
        &self.geom
    }

    /// The settings of the solve.
    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }

    fn side(site: &SurfaceSite) -> u32 {
        site.surface.0 * 2 + u32::from(site.back)
    }

    /// Reflected radiance leaving `from` towards `to` (emission excluded):
    /// the Lambertian part from the leaf element containing the point, plus
    /// the stored part from the deepest node of hierarchy (from, to) whose
    /// elements contain both points (paper Fig. 11c).
    pub fn radiance(&self, from: &SurfaceSite, to: &SurfaceSite) -> Spectrum<N> {
        let leaf = self.geom.locate(from.surface, from.coord);
        let mut l = self.radiance[usize::from(from.back)][leaf.index()];
        if let Some(&h) = self.by_sides.get(&(Self::side(from), Self::side(to))) {
            l += self.hierarchies[h as usize].radiance_at(&self.geom, from.coord, to.coord);
        }
        l
    }

    /// The Lambertian (two-point) reflected radiance alone at a point.
    pub fn lambertian_radiance(&self, from: &SurfaceSite) -> Spectrum<N> {
        let leaf = self.geom.locate(from.surface, from.coord);
        self.radiance[usize::from(from.back)][leaf.index()]
    }

    /// Area mean of the Lambertian (two-point) reflected radiance over one
    /// face of an input surface: its leaf elements' radiance weighted by
    /// their exposed areas, over the face's whole area (buried parts send
    /// nothing). For a diffuse scene solved in two-point mode this is
    /// the face's mean exitant radiance less emission, which a path tracer's
    /// irradiance meter gives independently as ρ Ē / π.
    pub fn surface_mean_radiance(&self, surface: SurfaceId, back: bool) -> Spectrum<N> {
        let mut sum = Spectrum::<N>::zero();
        let mut area = 0.0;
        let mut stack = vec![self.geom.surface(surface).root];
        while let Some(id) = stack.pop() {
            let e = self.geom.element(id);
            if let Some(children) = e.children() {
                stack.extend(children);
            } else {
                sum += self.radiance[usize::from(back)][id.index()]
                    * self.exposed_area[usize::from(back)][id.index()];
                area += e.area;
            }
        }
        if area > 0.0 { sum * (1.0 / area) } else { sum }
    }

    /// [`Solution::surface_mean_radiance`] over all the input surfaces of
    /// one shape (a cube's six faces, a mesh's charts), area-weighted.
    pub fn shape_mean_radiance(&self, shape: u32, back: bool) -> Spectrum<N> {
        let mut sum = Spectrum::<N>::zero();
        let mut area = 0.0;
        for s in self.geom.surfaces_of_shape(shape) {
            let a = self.geom.surface(s).area();
            sum += self.surface_mean_radiance(s, back) * a;
            area += a;
        }
        if area > 0.0 { sum * (1.0 / area) } else { sum }
    }

    /// Flux π Σ T L carried by the stored interaction from one face to
    /// another (flux-weighted over its hierarchy, so it is the root's
    /// π T L), if that interaction exists.
    pub fn interaction_flux(
        &self,
        from: (SurfaceId, bool),
        to: (SurfaceId, bool),
    ) -> Option<Spectrum<N>> {
        let key = (
            from.0.0 * 2 + u32::from(from.1),
            to.0.0 * 2 + u32::from(to.1),
        );
        let h = &self.hierarchies[*self.by_sides.get(&key)? as usize];
        let root = &h.nodes[0];
        Some(root.radiance * (std::f64::consts::PI * root.t))
    }

    /// The smallest radiance value (any band, any element or node) of the
    /// solution; NaN if any value is not finite.
    pub fn min_radiance(&self) -> f64 {
        let mut min = f64::INFINITY;
        let mut visit = |s: &Spectrum<N>| {
            for b in 0..N {
                if !s[b].is_finite() {
                    min = f64::NAN;
                } else if !min.is_nan() {
                    min = min.min(s[b]);
                }
            }
        };
        for side in &self.radiance {
            side.iter().for_each(&mut visit);
        }
        for h in &self.hierarchies {
            h.nodes.iter().for_each(|n| visit(&n.radiance));
        }
        min
    }

    /// Number of stored interaction hierarchies and of their nodes.
    pub fn interaction_counts(&self) -> (usize, usize) {
        (
            self.hierarchies.len(),
            self.hierarchies.iter().map(|h| h.nodes.len()).sum(),
        )
    }

    /// Whether the solution has stored (direction-dependent) radiance from
    /// `from`'s face towards `to`'s face.
    pub fn has_stored(&self, from: &SurfaceSite, to: &SurfaceSite) -> bool {
        self.by_sides
            .contains_key(&(Self::side(from), Self::side(to)))
    }
}

// ---------------------------------------------------------------------------
// File format
// ---------------------------------------------------------------------------

const MAGIC: &[u8; 8] = b"TRILUXS\0";
/// Version of the solution file format.
pub const FORMAT_VERSION: u32 = 2;

/// FNV-1a, 64 bits: stable across platforms and Rust versions.
fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// The hash of everything a solve depends on: geometry, materials,
/// emitters, the number of bands and the solver settings (not the camera,
/// film or sampler).
pub fn solve_hash(input: &SolverInput<'_>, settings: &SolverSettings, bands: usize) -> u64 {
    let text = serde_json::to_string(&(input.shapes, input.bsdfs, input.emission, settings, bands))
        .unwrap_or_default();
    fnv1a(text.as_bytes())
}

struct Writer<W: Write>(W);

impl<W: Write> Writer<W> {
    fn u8(&mut self, v: u8) -> std::io::Result<()> {
        self.0.write_all(&[v])
    }
    fn u32(&mut self, v: u32) -> std::io::Result<()> {
        self.0.write_all(&v.to_le_bytes())
    }
    fn u64(&mut self, v: u64) -> std::io::Result<()> {
        self.0.write_all(&v.to_le_bytes())
    }
    fn f64(&mut self, v: f64) -> std::io::Result<()> {
        self.0.write_all(&v.to_le_bytes())
    }
    fn spectrum<const N: usize>(&mut self, s: &Spectrum<N>) -> std::io::Result<()> {
        for b in 0..N {
            self.0.write_all(&(s[b] as f32).to_le_bytes())?;
        }
        Ok(())
    }
}

struct Reader<R: Read>(R);

impl<R: Read> Reader<R> {
    fn bytes<const K: usize>(&mut self) -> std::io::Result<[u8; K]> {
        let mut b = [0u8; K];
        self.0.read_exact(&mut b)?;
        Ok(b)
    }
    fn u8(&mut self) -> std::io::Result<u8> {
        Ok(self.bytes::<1>()?[0])
    }
    fn u32(&mut self) -> std::io::Result<u32> {
        Ok(u32::from_le_bytes(self.bytes()?))
    }
    fn u64(&mut self) -> std::io::Result<u64> {
        Ok(u64::from_le_bytes(self.bytes()?))
    }
    fn f64(&mut self) -> std::io::Result<f64> {
        Ok(f64::from_le_bytes(self.bytes()?))
    }
    fn spectrum<const N: usize>(&mut self) -> std::io::Result<Spectrum<N>> {
        let mut s = Spectrum::zero();
        for b in 0..N {
            s[b] = f64::from(f32::from_le_bytes(self.bytes()?));
        }
        Ok(s)
    }
}

impl<const N: usize> Solution<N> {
    /// Writes the solution to `path` (atomically: a temporary file renamed
    /// into place). `hash` is [`solve_hash`] of the scene it was made for.
    pub fn save(&self, path: &Path, hash: u64) -> Result<(), SolverError> {
        let io = |source| SolverError::Io {
            path: path.display().to_string(),
            source,
        };
        let tmp = path.with_extension("tmp-trilux");
        let file = std::fs::File::create(&tmp).map_err(io)?;
        let result = self.write_to(std::io::BufWriter::new(file), hash);
        if let Err(e) = result {
            let _ = std::fs::remove_file(&tmp);
            return Err(io(e));
        }
        std::fs::rename(&tmp, path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            io(e)
        })
    }

    fn write_to<W: Write>(&self, w: W, hash: u64) -> std::io::Result<()> {
        let mut w = Writer(w);
        w.0.write_all(MAGIC)?;
        w.u32(FORMAT_VERSION)?;
        w.u64(hash)?;
        w.u32(N as u32)?;
        let stats = serde_json::to_vec(&self.stats).map_err(std::io::Error::other)?;
        w.u64(stats.len() as u64)?;
        w.0.write_all(&stats)?;
        w.u32(self.depth_of.len() as u32)?;
        for &d in &self.depth_of {
            w.u32(d)?;
        }
        w.u64(self.radiance[0].len() as u64)?;
        for side in &self.radiance {
            for s in side {
                w.spectrum(s)?;
            }
        }
        for side in &self.exposed_area {
            for &a in side {
                w.f64(a)?;
            }
        }
        w.u32(self.hierarchies.len() as u32)?;
        for h in &self.hierarchies {
            w.u32(h.from)?;
            w.u32(h.to)?;
            w.u32(h.nodes.len() as u32)?;
            for n in &h.nodes {
                w.u32(n.from.0)?;
                w.u32(n.to.0)?;
                w.u32(n.first_child)?;
                w.u8(match n.split {
                    Split::None => 0,
                    Split::From => 1,
                    Split::To => 2,
                })?;
                w.f64(n.t)?;
                w.spectrum(&n.radiance)?;
            }
        }
        w.0.flush()
    }

    /// Reads a solution saved for the scene `input` with `settings`; refuses
    /// a file made for another scene, mode or setting.
    pub fn load(
        path: &Path,
        input: &SolverInput<'_>,
        settings: &SolverSettings,
    ) -> Result<Self, SolverError> {
        let shown = path.display().to_string();
        let bad = |message: String| SolverError::SolutionFile {
            path: shown.clone(),
            message,
        };
        let file = std::fs::File::open(path).map_err(|source| SolverError::Io {
            path: shown.clone(),
            source,
        })?;
        let mut r = Reader(std::io::BufReader::new(file));
        let truncated = |_| bad("truncated or unreadable solution file".into());
        let magic: [u8; 8] = r.bytes().map_err(truncated)?;
        if &magic != MAGIC {
            return Err(bad("not a trilux solution file".into()));
        }
        let version = r.u32().map_err(truncated)?;
        if version != FORMAT_VERSION {
            return Err(bad(format!(
                "solution file format version {version}, this trilux reads version {FORMAT_VERSION}"
            )));
        }
        let hash = r.u64().map_err(truncated)?;
        let bands = r.u32().map_err(truncated)? as usize;
        if bands != N {
            return Err(bad(format!(
                "solution has {bands} bands, the scene is solved in {N}"
            )));
        }
        if hash != solve_hash(input, settings, N) {
            return Err(bad(
                "solution was made for another scene or other solver settings (hash differs)"
                    .into(),
            ));
        }
        let len = r.u64().map_err(truncated)? as usize;
        if len > 1 << 26 {
            return Err(bad("corrupt statistics block".into()));
        }
        let mut stats_bytes = vec![0u8; len];
        r.0.read_exact(&mut stats_bytes).map_err(truncated)?;
        let stats: SolveStats = serde_json::from_slice(&stats_bytes)
            .map_err(|e| bad(format!("corrupt statistics: {e}")))?;

        let mut geom = SceneGeometry::build(input.shapes)?;
        let surfaces = r.u32().map_err(truncated)? as usize;
        if surfaces != geom.surfaces().len() {
            return Err(bad("surface count differs from the scene".into()));
        }
        let mut depth_of = Vec::with_capacity(surfaces);
        for _ in 0..surfaces {
            depth_of.push(r.u32().map_err(truncated)?.min(12));
        }
        presubdivide(&mut geom, &depth_of);
        let elements = r.u64().map_err(truncated)? as usize;
        if elements != geom.element_count() {
            return Err(bad("element count differs from the scene".into()));
        }
        let mut radiance = [Vec::with_capacity(elements), Vec::with_capacity(elements)];
        for side in &mut radiance {
            for _ in 0..elements {
                side.push(r.spectrum().map_err(truncated)?);
            }
        }
        let mut exposed_area = [Vec::with_capacity(elements), Vec::with_capacity(elements)];
        for side in &mut exposed_area {
            for _ in 0..elements {
                let a = r.f64().map_err(truncated)?;
                if !(a.is_finite() && a >= 0.0) {
                    return Err(bad("corrupt exposed area".into()));
                }
                side.push(a);
            }
        }
        let count = r.u32().map_err(truncated)? as usize;
        let sides = 2 * surfaces as u32;
        let mut hierarchies = Vec::with_capacity(count.min(1 << 24));
        for _ in 0..count {
            let from = r.u32().map_err(truncated)?;
            let to = r.u32().map_err(truncated)?;
            let n = r.u32().map_err(truncated)? as usize;
            if from >= sides || to >= sides {
                return Err(bad("corrupt interaction".into()));
            }
            let mut nodes = Vec::with_capacity(n.min(1 << 24));
            for _ in 0..n {
                let a = r.u32().map_err(truncated)?;
                let b = r.u32().map_err(truncated)?;
                let first_child = r.u32().map_err(truncated)?;
                let split = match r.u8().map_err(truncated)? {
                    0 => Split::None,
                    1 => Split::From,
                    2 => Split::To,
                    _ => return Err(bad("corrupt interaction node".into())),
                };
                let t = r.f64().map_err(truncated)?;
                let radiance = r.spectrum().map_err(truncated)?;
                if a as usize >= elements || b as usize >= elements {
                    return Err(bad("corrupt interaction node".into()));
                }
                nodes.push(Node {
                    from: trilux_geometry::ElementId(a),
                    to: trilux_geometry::ElementId(b),
                    first_child,
                    split,
                    t,
                    v: 1.0,
                    radiance,
                    unshot: Spectrum::zero(),
                    gathered: Spectrum::zero(),
                });
            }
            for node in &nodes {
                let ok = match node.split {
                    Split::None => node.first_child == NO_CHILD,
                    _ => (node.first_child as usize).saturating_add(4) <= nodes.len(),
                };
                if !ok {
                    return Err(bad("corrupt interaction tree".into()));
                }
            }
            hierarchies.push(Hierarchy {
                from,
                to,
                nodes,
                unshot_flux: Spectrum::zero(),
            });
        }
        let by_sides = hierarchies
            .iter()
            .enumerate()
            .map(|(i, h)| ((h.from, h.to), i as u32))
            .collect();
        Ok(Solution {
            geom,
            settings: settings.clone(),
            depth_of,
            exposed_area,
            radiance,
            hierarchies,
            by_sides,
            stats,
        })
    }
}
