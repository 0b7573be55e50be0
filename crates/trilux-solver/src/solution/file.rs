//! The solution file: a versioned little-endian binary format.
//!
//! ```text
//! header   "TRILUXS\0", version u32, solve hash u64, bands u32,
//!          payload length u64, payload checksum u64 (FNV-1a)
//! payload  statistics (u64 length + JSON)
//!          depth limit per input surface (u32 count + u32 each)
//!          element count u64; two-point radiance, front then back,
//!          N × f32 per element; exposed area, front then back, f64
//!          hierarchy count u32; per hierarchy: sender face u32,
//!          receiver face u32, node count u32, and per node: sender
//!          element u32, receiver element u32, first child u32, split u8,
//!          throughput f64, radiance N × f32
//!          gather links: row count u32 and row starts u32 (one per face
//!          element, plus the end), link count u32, and per link: sender
//!          element u32, sender face u32, source tag u8 (0 face, 1 node),
//!          source face or hierarchy u32, node u32, visibility f32
//!          far fields (version 5): count u32; per field: sender face u32,
//!          block count u32, and per block: cluster u32, radiance N × f32
//!          the residual's later bounces (version 6, `crate::local_ambient`):
//!          u8 0 (none) or 1, then front then back, N × f32 per element
//! ```
//!
//! The solve hash covers the scene description, the band count and the
//! solver settings ([`solve_hash`]), not the camera, film or sampler: a
//! solution is refused for any other scene, mode or setting, and renders
//! any view. On reading, the checksum is verified before anything is
//! parsed, every count is bounded by the bytes that remain, the depth
//! limits must be the ones the scene and settings give, and every value
//! must be finite and in range: a corrupted file is an error, never a
//! huge allocation or a silently different image.

use std::path::Path;
use std::sync::Arc;

use trilux_color::Spectrum;
use trilux_geometry::{ElementId, FaceId, Sided};

use super::{Parts, Solution};
use crate::discretisation::Discretisation;
use crate::error::SolverError;
use crate::gather_links::{GatherLink, GatherLinks, LinkSource};
use crate::interaction::{Hierarchy, NO_CHILD, Node, Split};
use crate::prepared::{Fnv1a, PreparedScene};
use crate::settings::SolverSettings;
use crate::stats::SolveStats;

const MAGIC: &[u8; 8] = b"TRILUXS\0";
/// Version of the solution file format.
pub const FORMAT_VERSION: u32 = 6;
/// Bytes of the header before the payload.
const HEADER_LEN: usize = 8 + 4 + 8 + 4 + 8 + 8;
/// The largest statistics block a reader accepts (64 MiB).
const MAX_STATS_LEN: usize = 1 << 26;
/// The largest solution file a reader accepts (4 GiB, docs/limits.md): far
/// beyond what the depth limits let a solve store for any scene that fits
/// in memory, and a bound on what a file can make the reader allocate.
pub const MAX_FILE_BYTES: u64 = 4 << 30;

/// The hash of everything a solve depends on: the scene description, the
/// band count (both in [`PreparedScene::content_hash`]) and the solver
/// settings (not the camera, film or sampler).
pub fn solve_hash<const N: usize>(
    scene: &PreparedScene<N>,
    settings: &SolverSettings,
) -> Result<u64, SolverError> {
    let mut h = Fnv1a::new();
    serde_json::to_writer(&mut h, &(scene.content_hash(), settings)).map_err(|source| {
        SolverError::Serialise {
            what: "the solver settings",
            source,
        }
    })?;
    Ok(h.0)
}

fn fnv(bytes: &[u8]) -> u64 {
    use std::io::Write;
    let mut h = Fnv1a::new();
    // Writing to a hasher cannot fail.
    let _ = h.write(bytes);
    h.0
}

/// Little-endian output into a byte buffer.
struct Out(Vec<u8>);

impl Out {
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn spectrum<const N: usize>(&mut self, s: &Spectrum<N>) {
        for b in 0..N {
            self.0.extend_from_slice(&(s[b] as f32).to_le_bytes());
        }
    }
}

/// Little-endian input from a byte slice; every read is bounds-checked.
struct In<'a> {
    bytes: &'a [u8],
    pos: usize,
}

/// A reading error before it is given the file's name.
type Bad = String;

impl In<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], Bad> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| "truncated solution file".to_string())?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn array<const K: usize>(&mut self) -> Result<[u8; K], Bad> {
        let mut a = [0u8; K];
        a.copy_from_slice(self.take(K)?);
        Ok(a)
    }
    fn u8(&mut self) -> Result<u8, Bad> {
        Ok(self.array::<1>()?[0])
    }
    fn u32(&mut self) -> Result<u32, Bad> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    fn u64(&mut self) -> Result<u64, Bad> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    fn f64(&mut self) -> Result<f64, Bad> {
        Ok(f64::from_le_bytes(self.array()?))
    }
    fn f32(&mut self) -> Result<f32, Bad> {
        Ok(f32::from_le_bytes(self.array()?))
    }
    /// A count of items of `size` bytes each, refused when the rest of the
    /// payload cannot hold them.
    fn count(&mut self, value: u64, size: usize, what: &str) -> Result<usize, Bad> {
        let remaining = (self.bytes.len() - self.pos) as u64;
        if value.saturating_mul(size as u64) > remaining {
            return Err(format!("corrupt {what} count {value}"));
        }
        Ok(value as usize)
    }
    /// A radiance spectrum, refused unless finite and non-negative.
    fn radiance<const N: usize>(&mut self) -> Result<Spectrum<N>, Bad> {
        let mut s = Spectrum::zero();
        for b in 0..N {
            s[b] = f64::from(f32::from_le_bytes(self.array()?));
        }
        if s.is_finite() && s.is_non_negative() {
            Ok(s)
        } else {
            Err("corrupt radiance (negative or not finite)".into())
        }
    }
}

impl<const N: usize> Solution<N> {
    /// The solution file's bytes (module docs), for a caller that writes
    /// several outputs at once (`trilux_files::write_all`).
    pub fn to_bytes(&self) -> Result<Vec<u8>, SolverError> {
        let hash = solve_hash(&self.scene, &self.settings)?;
        let payload = self.payload()?;
        let mut out = Out(Vec::with_capacity(HEADER_LEN + payload.len()));
        out.0.extend_from_slice(MAGIC);
        out.u32(FORMAT_VERSION);
        out.u64(hash);
        out.u32(N as u32);
        out.u64(payload.len() as u64);
        out.u64(fnv(&payload));
        out.0.extend_from_slice(&payload);
        Ok(out.0)
    }

    /// Writes the solution to `path` (a regular file is replaced only once
    /// the new one is complete; see `trilux_files`).
    pub fn save(&self, path: &Path) -> Result<(), SolverError> {
        let bytes = self.to_bytes()?;
        trilux_files::write_one(path, "solution", &bytes)?;
        Ok(())
    }

    /// The payload bytes (module docs).
    fn payload(&self) -> Result<Vec<u8>, SolverError> {
        let mut w = Out(Vec::new());
        let stats = serde_json::to_vec(&self.stats).map_err(|source| SolverError::Serialise {
            what: "the statistics",
            source,
        })?;
        w.u64(stats.len() as u64);
        w.0.extend_from_slice(&stats);
        let depths = self.discretisation.depth_limits();
        w.u32(depths.len() as u32);
        for &d in depths {
            w.u32(d);
        }
        w.u64(self.radiance.front.len() as u64);
        for (_, side) in self.radiance.iter() {
            side.iter().for_each(|s| w.spectrum(s));
        }
        for (_, side) in self.exposed_area.iter() {
            side.iter().for_each(|&a| w.f64(a));
        }
        w.u32(self.hierarchies.len() as u32);
        for h in &self.hierarchies {
            w.u32(h.from.0);
            w.u32(h.to.0);
            w.u32(h.nodes.len() as u32);
            for n in &h.nodes {
                w.u32(n.from.0);
                w.u32(n.to.0);
                w.u32(n.first_child);
                w.u8(match n.split {
                    Split::None => 0,
                    Split::From => 1,
                    Split::To => 2,
                });
                w.f64(n.t);
                w.spectrum(&n.radiance);
            }
        }
        write_links(&mut w, &self.links);
        w.u32(self.far.len() as u32);
        for f in &self.far {
            w.u32(f.face.0);
            w.u32(f.blocks.len() as u32);
            for (c, l) in &f.blocks {
                w.u32(*c);
                w.spectrum(l);
            }
        }
        match self.ambient.local() {
            Some(local) => {
                w.u8(1);
                for (_, side) in local.iter() {
                    side.iter().for_each(|s| w.spectrum(s));
                }
            }
            None => w.u8(0),
        }
        Ok(w.0)
    }

    /// Reads a solution saved for `scene` with `settings`; refuses a file
    /// made for another scene, mode or setting, and any corruption (module
    /// docs).
    pub fn load(
        path: &Path,
        scene: Arc<PreparedScene<N>>,
        settings: &SolverSettings,
    ) -> Result<Self, SolverError> {
        let shown = path.display().to_string();
        let bytes = trilux_files::read_limited(path, MAX_FILE_BYTES).map_err(|source| {
            SolverError::Read {
                path: shown.clone(),
                source,
            }
        })?;
        Self::from_bytes(&bytes, scene, settings).map_err(|message| SolverError::SolutionFile {
            path: shown,
            message,
        })
    }

    /// Reads a solution from the bytes of its file; the error says what is
    /// wrong (the caller names the file). Never panics, and allocates no
    /// more than the scene's element trees and a small multiple of
    /// `bytes.len()`, whatever the bytes (module docs).
    pub fn from_bytes(
        bytes: &[u8],
        scene: Arc<PreparedScene<N>>,
        settings: &SolverSettings,
    ) -> Result<Self, String> {
        let hash = solve_hash(&scene, settings).map_err(|e| e.to_string())?;
        let payload = check_header::<N>(bytes, hash)?;
        Self::parse(payload, scene, settings)
    }

    /// The payload of a verified file (module docs).
    fn parse(
        payload: &[u8],
        scene: Arc<PreparedScene<N>>,
        settings: &SolverSettings,
    ) -> Result<Self, Bad> {
        let mut r = In {
            bytes: payload,
            pos: 0,
        };
        let len = r.u64()?;
        let len = r.count(len, 1, "statistics")?;
        if len > MAX_STATS_LEN {
            return Err("corrupt statistics block".into());
        }
        let stats: SolveStats =
            serde_json::from_slice(r.take(len)?).map_err(|e| format!("corrupt statistics: {e}"))?;
        // The file records the depth limits its elements were made with:
        // they must be this discretisation's, or the element indexes below
        // would mean other elements.
        // Compared before the trees are built, so a file for another
        // discretisation costs no subdivision.
        let depths = Discretisation::limits(scene.geometry(), settings);
        let surfaces = r.u32()? as usize;
        if surfaces != depths.len() {
            return Err("surface count differs from the scene".into());
        }
        for &d in &depths {
            if r.u32()? != d {
                return Err("element depth limits differ from the scene's".into());
            }
        }
        let discretisation = Discretisation::with_limits(scene.geometry(), depths);
        let forest = discretisation.forest();
        let elements = r.u64()?;
        if elements != forest.element_count() as u64 {
            return Err("element count differs from the scene".into());
        }
        let radiance = read_sided(&mut r, |r| r.radiance::<N>(), forest.element_count())?;
        let exposed_area = read_sided(&mut r, read_area, forest.element_count())?;
        let faces = 2 * surfaces as u32;
        let hierarchies = read_hierarchies::<N>(&mut r, faces, elements as u32)?;
        let links = read_links(&mut r, faces, elements as u32, &hierarchies)?;
        let clusters = (2 * surfaces).saturating_sub(1) as u32;
        let far = read_far::<N>(&mut r, faces, clusters)?;
        let local_ambient = match r.u8()? {
            0 => None,
            1 => Some(read_sided(
                &mut r,
                |r| r.radiance::<N>(),
                forest.element_count(),
            )?),
            _ => return Err("corrupt ambient block".into()),
        };
        if r.pos != payload.len() {
            return Err("trailing bytes after the solution".into());
        }
        Ok(Solution::assemble(Parts {
            scene,
            discretisation,
            settings: settings.clone(),
            exposed_area,
            radiance,
            hierarchies,
            far,
            links,
            stats,
            local_ambient,
        }))
    }
}

/// Checks magic, version, band count, hash and checksum; returns the
/// payload.
fn check_header<const N: usize>(bytes: &[u8], hash: u64) -> Result<&[u8], Bad> {
    let mut r = In { bytes, pos: 0 };
    if r.take(8).ok() != Some(MAGIC.as_slice()) {
        return Err("not a trilux solution file".into());
    }
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "solution file format version {version}, this trilux reads version {FORMAT_VERSION}"
        ));
    }
    let file_hash = r.u64()?;
    let bands = r.u32()? as usize;
    if bands != N {
        return Err(format!(
            "solution has {bands} bands, the scene is solved in {N}"
        ));
    }
    if file_hash != hash {
        return Err(
            "solution was made for another scene or other solver settings (hash differs)".into(),
        );
    }
    let len = r.u64()?;
    let checksum = r.u64()?;
    let payload = &bytes[HEADER_LEN..];
    if len != payload.len() as u64 {
        return Err(format!(
            "truncated or extended solution file ({} payload bytes, the header says {len})",
            payload.len()
        ));
    }
    if fnv(payload) != checksum {
        return Err("corrupt solution file (checksum mismatch)".into());
    }
    Ok(payload)
}

/// An exposed area: finite and non-negative.
fn read_area(r: &mut In<'_>) -> Result<f64, Bad> {
    let a = r.f64()?;
    if a.is_finite() && a >= 0.0 {
        Ok(a)
    } else {
        Err("corrupt exposed area".into())
    }
}

/// `count` values for the front, then `count` for the back.
fn read_sided<T>(
    r: &mut In<'_>,
    mut read: impl FnMut(&mut In<'_>) -> Result<T, Bad>,
    count: usize,
) -> Result<Sided<Vec<T>>, Bad> {
    let mut side = |r: &mut In<'_>| (0..count).map(|_| read(r)).collect::<Result<Vec<T>, Bad>>();
    let front = side(r)?;
    let back = side(r)?;
    Ok(Sided { front, back })
}

/// Bytes of one stored node with `N` bands.
const fn node_bytes(n: usize) -> usize {
    4 + 4 + 4 + 1 + 8 + 4 * n
}

fn read_hierarchies<const N: usize>(
    r: &mut In<'_>,
    faces: u32,
    elements: u32,
) -> Result<Vec<Hierarchy<N>>, Bad> {
    let count = r.u32()?;
    let count = r.count(u64::from(count), 12, "interaction")?;
    let mut out = Vec::with_capacity(count);
    for _ in 0..count {
        let (from, to) = (r.u32()?, r.u32()?);
        if from >= faces || to >= faces {
            return Err("corrupt interaction (face out of range)".into());
        }
        let n = r.u32()?;
        let n = r.count(u64::from(n), node_bytes(N), "interaction node")?;
        let nodes = (0..n)
            .map(|_| read_node::<N>(r, elements))
            .collect::<Result<Vec<_>, Bad>>()?;
        check_tree(&nodes)?;
        out.push(Hierarchy {
            from: FaceId(from),
            to: FaceId(to),
            nodes,
            unshot_flux: Spectrum::zero(),
            pending: false,
        });
    }
    Ok(out)
}

fn read_node<const N: usize>(r: &mut In<'_>, elements: u32) -> Result<Node<N>, Bad> {
    let (a, b, first_child) = (r.u32()?, r.u32()?, r.u32()?);
    let split = match r.u8()? {
        0 => Split::None,
        1 => Split::From,
        2 => Split::To,
        _ => return Err("corrupt interaction node (split)".into()),
    };
    let t = r.f64()?;
    let radiance = r.radiance::<N>()?;
    if a >= elements || b >= elements {
        return Err("corrupt interaction node (element out of range)".into());
    }
    if !(t.is_finite() && t >= 0.0) {
        return Err("corrupt interaction node (throughput)".into());
    }
    Ok(Node {
        from: ElementId(a),
        to: ElementId(b),
        first_child,
        split,
        t,
        v: 1.0,
        spread: 0.0,
        radiance,
        unshot: Spectrum::zero(),
        gathered: Spectrum::zero(),
    })
}

fn write_links(w: &mut Out, links: &GatherLinks) {
    let (offsets, all) = links.raw();
    w.u32(offsets.len() as u32);
    offsets.iter().for_each(|&o| w.u32(o));
    w.u32(all.len() as u32);
    for l in all {
        w.u32(l.sender.0);
        w.u32(l.sender_face.0);
        match l.source {
            LinkSource::Face(f) => {
                w.u8(0);
                w.u32(f.0);
                w.u32(0);
            }
            LinkSource::Node { hierarchy, node } => {
                w.u8(1);
                w.u32(hierarchy);
                w.u32(node);
            }
        }
        w.f32(l.visibility);
    }
}

/// Bytes of one gather link in the file.
const LINK_BYTES: usize = 4 + 4 + 1 + 4 + 4 + 4;

/// The far fields (module docs): faces and clusters in range, radiance
/// finite and non-negative, each face once.
fn read_far<const N: usize>(
    r: &mut In<'_>,
    faces: u32,
    clusters: u32,
) -> Result<Vec<super::FarRecord<N>>, Bad> {
    let count = r.u32()?;
    let count = r.count(u64::from(count), 8, "far field")?;
    let mut out: Vec<super::FarRecord<N>> = Vec::with_capacity(count);
    for _ in 0..count {
        let face = r.u32()?;
        if face >= faces || out.last().is_some_and(|l| l.face.0 >= face) {
            return Err("corrupt far field (face out of range or order)".into());
        }
        let n = r.u32()?;
        let n = r.count(u64::from(n), 4 + 4 * N, "far block")?;
        let blocks = (0..n)
            .map(|_| {
                let c = r.u32()?;
                if c >= clusters {
                    return Err("corrupt far block (cluster out of range)".to_string());
                }
                Ok((c, r.radiance::<N>()?))
            })
            .collect::<Result<Vec<_>, Bad>>()?;
        out.push(super::FarRecord {
            face: FaceId(face),
            blocks,
        });
    }
    Ok(out)
}

fn read_links<const N: usize>(
    r: &mut In<'_>,
    faces: u32,
    elements: u32,
    hierarchies: &[Hierarchy<N>],
) -> Result<GatherLinks, Bad> {
    let rows = r.u32()?;
    if u64::from(rows) != 2 * u64::from(elements) + 1 {
        return Err("corrupt gather links (row count)".into());
    }
    let rows = r.count(u64::from(rows), 4, "gather link row")?;
    let offsets = (0..rows)
        .map(|_| r.u32())
        .collect::<Result<Vec<_>, Bad>>()?;
    let count = r.u32()?;
    let count = r.count(u64::from(count), LINK_BYTES, "gather link")?;
    let links = (0..count)
        .map(|_| read_link(r, faces, elements, hierarchies))
        .collect::<Result<Vec<_>, Bad>>()?;
    GatherLinks::from_raw(offsets, links)
}

fn read_link<const N: usize>(
    r: &mut In<'_>,
    faces: u32,
    elements: u32,
    hierarchies: &[Hierarchy<N>],
) -> Result<GatherLink, Bad> {
    let (sender, sender_face, tag, a, b) = (r.u32()?, r.u32()?, r.u8()?, r.u32()?, r.u32()?);
    let visibility = r.f32()?;
    let bad = |what: &str| Err(format!("corrupt gather link ({what})"));
    if sender >= elements || sender_face >= faces {
        return bad("sender out of range");
    }
    let source = match tag {
        0 if a < faces => LinkSource::Face(FaceId(a)),
        1 if hierarchies
            .get(a as usize)
            .is_some_and(|h| (b as usize) < h.nodes.len()) =>
        {
            LinkSource::Node {
                hierarchy: a,
                node: b,
            }
        }
        _ => return bad("source"),
    };
    if !(visibility.is_finite() && (0.0..=1.0).contains(&visibility)) {
        return bad("visibility");
    }
    Ok(GatherLink {
        sender: ElementId(sender),
        sender_face: FaceId(sender_face),
        source,
        visibility,
    })
}

/// Every split node's four children exist and come after it (so that every
/// descent ends).
fn check_tree<const N: usize>(nodes: &[Node<N>]) -> Result<(), Bad> {
    for (k, node) in nodes.iter().enumerate() {
        let ok = match node.split {
            Split::None => node.first_child == NO_CHILD,
            _ => {
                let first = node.first_child as usize;
                first > k && first.saturating_add(4) <= nodes.len()
            }
        };
        if !ok {
            return Err("corrupt interaction tree".into());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use trilux_geometry::Side;

    #[test]
    fn side_order_is_front_then_back() {
        // The format stores the front's values first.
        let s = Sided {
            front: vec![1],
            back: vec![2],
        };
        let order: Vec<Side> = s.iter().map(|(side, _)| side).collect();
        assert_eq!(order, [Side::Front, Side::Back]);
    }
}
