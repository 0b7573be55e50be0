//! Stage 3 of loading: resolve `<ref id>` against the objects that carry an
//! `id` (every object type trilux reads: `<bsdf>`, `<texture>`,
//! `<emitter>`, and a sensor's `<film>`, `<sampler>` and a film's
//! `<rfilter>`), and count `<bsdf>` elements.
//!
//! After this pass the tree has no `<ref>` left: each reference is replaced
//! by a copy of the element it names (BSDF parameters are plain data, and
//! the texture cache reads an image once however many copies name it, so a
//! copy is as good as sharing). BSDFs, textures, emitters, films, samplers
//! and filters can be referenced (an emitter from one shape only, as in
//! Mitsuba);
//! a texture's copy takes the `name` of its `<ref>` (the parameter it
//! gives, as in Mitsuba).
//!
//! A reference to a BSDF that is being expanded is a cycle, refused as
//! one; the expanded tree is bounded in depth and in size
//! (`crate::limits`), since references can nest and multiply.
//!
//! Each top-level element is checked on its own: its errors are collected
//! and it is left as written, marked failed, for `build` to skip, so that
//! one run reports the errors of every top-level object. An element that
//! references a failed definition fails with the definition's error
//! (reported once). A limit passed stops at once.

use std::collections::{BTreeMap, HashMap};

use crate::error::{Errors, Result, SceneError};
use crate::limits::{MAX_DEPTH, MAX_ELEMENTS};
use crate::xml::Element;

/// The tree with references replaced, and how many `<bsdf>` elements of each
/// type the file holds (nested ones included, each written element once).
pub(crate) struct Resolved {
    /// The `<scene>` element, without `<ref>`s in the children that did
    /// not fail.
    pub scene: Element,
    /// For each child of `<scene>`: true when its references failed (its
    /// errors are in `errors`; it is left as written, for the next stage
    /// to skip).
    pub failed: Vec<bool>,
    /// `<bsdf>` type → number of `<bsdf>` elements written with it.
    pub bsdf_counts: BTreeMap<String, usize>,
    /// The errors found so far, each at its top-level element's place
    /// (index + 1; the `<scene>` element is 0).
    pub errors: Errors,
}

/// Resolves references in `scene`: every reference is checked first,
/// without copying (so that a file whose references multiply is refused in
/// time proportional to the file, not to its expansion), then copied. The
/// errors of each top-level object are collected; a limit passed stops at
/// once.
pub(crate) fn resolve(scene: &Element) -> Result<Resolved> {
    let mut errors = Errors::default();
    let mut failed = vec![false; scene.children.len()];
    let mut ids: HashMap<String, &Element> = HashMap::new();
    let mut seen_emitters = HashMap::new();
    for (k, child) in scene.children.iter().enumerate() {
        let mut found = Vec::new();
        collect_ids(child, &mut ids, &mut found);
        failed[k] = !found.is_empty();
        found.into_iter().for_each(|e| errors.push_at(k + 1, e));
    }
    for (k, child) in scene.children.iter().enumerate() {
        let mut found = Vec::new();
        refuse_shared_emitters(child, &ids, &mut seen_emitters, &mut found);
        failed[k] |= !found.is_empty();
        found.into_iter().for_each(|e| errors.push_at(k + 1, e));
    }
    let mut bsdf_counts = BTreeMap::new();
    count_bsdfs(scene, &mut bsdf_counts);
    let mut checker = Checker::new(&ids);
    checker.elements = 1;
    for (k, child) in scene.children.iter().enumerate() {
        checker.expanding.clear();
        let checked = if child.tag == "ref" {
            checker.check_reference(child, 1)
        } else {
            checker.check(child, 2)
        };
        match checked {
            Ok(_) => {}
            Err(e) if checker.over_limit => return Err(errors.stop(e)),
            Err(e) => {
                failed[k] = true;
                errors.push_at(k + 1, e);
            }
        }
    }
    let mut children = Vec::with_capacity(scene.children.len());
    for (child, &failed) in scene.children.iter().zip(&failed) {
        children.push(if failed {
            child.clone()
        } else {
            copy_child(&ids, child)?
        });
    }
    let scene = Element {
        tag: scene.tag.clone(),
        attrs: scene.attrs.clone(),
        children,
        loc: scene.loc.clone(),
    };
    Ok(Resolved {
        scene,
        failed,
        bsdf_counts,
        errors,
    })
}

/// Registers the ids of `e` and the elements in it; an id used twice is
/// an error in `found` (the first use keeps it).
fn collect_ids<'a>(
    e: &'a Element,
    ids: &mut HashMap<String, &'a Element>,
    found: &mut Vec<SceneError>,
) {
    if e.tag != "ref"
        && let Some(id) = e.attr("id")
    {
        if let Some(first) = ids.get(&id.value) {
            found.push(SceneError::at(
                &id.loc,
                format!(
                    "id \"{}\" is already used by the {} at line {}",
                    id.value,
                    first.describe(),
                    first.loc.line
                ),
            ));
        } else {
            ids.insert(id.value.clone(), e);
        }
    }
    for child in &e.children {
        collect_ids(child, ids, found);
    }
}

/// An area emitter belongs to one shape: a second `<ref>` to one is
/// refused (an error in `found`), as Mitsuba refuses it ("an endpoint can
/// only be attached to a single shape"). `seen` maps an emitter's id to
/// its first reference's line.
fn refuse_shared_emitters<'a>(
    e: &'a Element,
    ids: &HashMap<String, &Element>,
    seen: &mut HashMap<&'a str, u32>,
    found: &mut Vec<SceneError>,
) {
    if e.tag == "ref"
        && let Some(id) = e.attr("id")
        && ids.get(&id.value).is_some_and(|t| t.tag == "emitter")
        && let Some(line) = seen.insert(&id.value, e.loc.line)
    {
        found.push(SceneError::at(
            &e.loc,
            format!(
                "emitter \"{}\" is already attached to the shape at line {line}; an area emitter belongs to one shape (as in Mitsuba): define one per shape",
                id.value
            ),
        ));
    }
    for child in &e.children {
        refuse_shared_emitters(child, ids, seen, found);
    }
}

fn count_bsdfs(e: &Element, counts: &mut BTreeMap<String, usize>) {
    for child in &e.children {
        if child.tag == "bsdf" {
            let t = child.attr("type").map_or("?", |a| a.value.as_str());
            *counts.entry(t.to_string()).or_default() += 1;
        }
        count_bsdfs(child, counts);
    }
}

/// What an element becomes once its references are expanded: how many
/// elements, and how many levels (itself being one).
#[derive(Clone, Copy, Debug)]
struct Extent {
    elements: usize,
    height: usize,
}

/// Walks the tree as its expansion would be walked, in document order,
/// counting elements and levels and finding the errors, but without copying:
/// an element with an id that was checked once is not walked again where it
/// fits within the limits, so the walk is linear in the file.
struct Checker<'a> {
    ids: &'a HashMap<String, &'a Element>,
    /// Elements of the expansion counted so far.
    elements: usize,
    /// Elements actually walked (what the walk costs).
    walked: usize,
    /// The ids of the elements being expanded, outermost first.
    expanding: Vec<&'a str>,
    /// Elements with an id whose whole expansion is valid, by id.
    checked: HashMap<&'a str, Extent>,
    /// True once the expansion passed a limit: loading stops there.
    over_limit: bool,
}

impl<'a> Checker<'a> {
    fn new(ids: &'a HashMap<String, &'a Element>) -> Self {
        Checker {
            ids,
            elements: 0,
            walked: 0,
            expanding: Vec::new(),
            checked: HashMap::new(),
            over_limit: false,
        }
    }

    /// Checks the expansion of `e` at nesting `depth` (`<scene>` being 1);
    /// the errors are those of the first element, in the expansion's
    /// document order, that breaks a rule.
    fn check(&mut self, e: &'a Element, depth: usize) -> Result<Extent> {
        if depth > MAX_DEPTH {
            self.over_limit = true;
            return Err(SceneError::at(
                &e.loc,
                format!(
                    "elements nest more than {MAX_DEPTH} deep once references are expanded, the limit (docs/limits.md)"
                ),
            ));
        }
        self.walked += 1;
        self.elements += 1;
        if self.elements > MAX_ELEMENTS {
            self.over_limit = true;
            return Err(SceneError::at(
                &e.loc,
                format!(
                    "references expand the scene to more than {MAX_ELEMENTS} elements, the limit (docs/limits.md)"
                ),
            ));
        }
        let id = e.attr("id").map(|a| a.value.as_str());
        self.expanding.extend(id);
        let mut extent = Extent {
            elements: 1,
            height: 1,
        };
        for child in &e.children {
            let inner = if child.tag == "ref" {
                self.check_reference(child, depth)?
            } else {
                self.check(child, depth + 1)?
            };
            extent.elements += inner.elements;
            extent.height = extent.height.max(inner.height + 1);
        }
        if let Some(id) = id {
            self.expanding.pop();
            self.checked.insert(id, extent);
        }
        Ok(extent)
    }

    /// Checks the expansion of `<ref>` element `r`, a child at `depth`.
    fn check_reference(&mut self, r: &'a Element, depth: usize) -> Result<Extent> {
        let (name, target) = target(self.ids, r)?;
        if self.expanding.contains(&name) {
            let mut chain = self.expanding.clone();
            chain.push(name);
            let start = chain.iter().position(|n| *n == name).unwrap_or(0);
            return Err(SceneError::at(
                &r.required("id")?.loc,
                format!("reference cycle: {}", chain[start..].join(" → ")),
            ));
        }
        // A valid expansion stays valid wherever it is put, as long as it
        // fits: it cannot reach an element being expanded here, since then
        // it would have reached itself when it was checked.
        if let Some(&extent) = self.checked.get(name)
            && self.elements + extent.elements <= MAX_ELEMENTS
            && depth + extent.height <= MAX_DEPTH
        {
            self.elements += extent.elements;
            return Ok(extent);
        }
        self.check(target, depth + 1)
    }
}

/// The id and the element that `<ref>` element `r` names.
fn target<'a>(
    ids: &'a HashMap<String, &'a Element>,
    r: &Element,
) -> Result<(&'a str, &'a Element)> {
    r.check_attrs(&["id", "name"])?;
    let id = r.required("id")?;
    let (name, target) = ids.get_key_value(&id.value).ok_or_else(|| {
        SceneError::at(&id.loc, format!("reference to unknown id \"{}\"", id.value))
    })?;
    if !matches!(
        target.tag.as_str(),
        "bsdf" | "texture" | "emitter" | "film" | "sampler" | "rfilter"
    ) {
        return Err(SceneError::at(
            &id.loc,
            format!(
                "\"{}\" names a {}; only <bsdf>, <texture>, <emitter>, <film>, <sampler> and <rfilter> elements can be referenced (trilux reads no shape groups)",
                id.value,
                target.describe()
            ),
        ));
    }
    if !r.children.is_empty() {
        return Err(SceneError::at(&r.loc, "<ref> has no child elements"));
    }
    Ok((name.as_str(), target))
}

/// A copy of checked element `e` with each `<ref>` replaced by a copy of
/// what it names.
fn copy(ids: &HashMap<String, &Element>, e: &Element) -> Result<Element> {
    let mut children = Vec::with_capacity(e.children.len());
    for child in &e.children {
        children.push(copy_child(ids, child)?);
    }
    Ok(Element {
        tag: e.tag.clone(),
        attrs: e.attrs.clone(),
        children,
        loc: e.loc.clone(),
    })
}

/// A copy of checked element `child`, or of what it names if it is a
/// `<ref>`.
fn copy_child(ids: &HashMap<String, &Element>, child: &Element) -> Result<Element> {
    if child.tag != "ref" {
        return copy(ids, child);
    }
    let (_, named) = target(ids, child)?;
    let mut c = copy(ids, named)?;
    if named.tag == "texture" {
        // Placed where the <ref> is: errors of its use point there.
        c.loc = child.loc.clone();
        if let Some(name) = child.attr("name") {
            c.attrs.retain(|a| a.name != "name");
            c.attrs.push(name.clone());
        }
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use std::path::Path;
    use std::sync::Arc;

    use super::*;

    /// `levels` BSDFs, each a blend of the previous one twice: 2^levels
    /// elements once expanded.
    fn doubling_chain(levels: usize) -> Element {
        let mut text =
            String::from("<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\" id=\"b0\"/>\n");
        for i in 1..levels {
            text += &format!(
                "<bsdf type=\"blendbsdf\" id=\"b{i}\"><ref id=\"b{0}\"/><ref id=\"b{0}\"/></bsdf>\n",
                i - 1
            );
        }
        text += "</scene>";
        let file: Arc<Path> = Arc::from(Path::new("chain.xml"));
        crate::xml::parse(&text, &file, &[])
            .expect("the chain parses")
            .0
    }

    fn walk(levels: usize) -> (Result<Extent>, usize) {
        let tree = doubling_chain(levels);
        let mut ids = HashMap::new();
        let mut found = Vec::new();
        collect_ids(&tree, &mut ids, &mut found);
        assert!(found.is_empty(), "ids are unique");
        let mut checker = Checker::new(&ids);
        let result = checker.check(&tree, 1);
        (result, checker.walked)
    }

    /// The count is exact: the scene, and b_i expanding to 2^(i+1) − 1
    /// elements, so Σ_{i<n} (2^(i+1) − 1) + 1 = 2^(n+1) − n − 1.
    #[test]
    fn the_expansion_is_counted_exactly() {
        for n in [1, 5, 12] {
            let (result, _) = walk(n);
            let extent = result.expect("small chains are within the limits");
            assert_eq!(extent.elements, (1 << (n + 1)) - n - 1, "{n} levels");
            assert_eq!(extent.height, n + 1, "{n} levels");
        }
    }

    /// A file whose expansion passes the limit is refused after walking a
    /// number of elements proportional to the file, not to the limit: 40
    /// levels expand to 2^41 elements, the limit (~2^20) is passed inside
    /// b20, and the walk visits each BSDF before it once plus one descent
    /// of about 20 (38 measured). Copying instead of walking would visit
    /// the million elements.
    #[test]
    fn refusing_an_exponential_file_walks_only_the_file() {
        let (result, walked) = walk(40);
        let message = result
            .expect_err("2^41 elements are over the limit")
            .to_string();
        assert!(message.contains("more than 1000000 elements"), "{message}");
        eprintln!("refused after walking {walked} elements");
        assert!(walked < 40 * 40, "walked {walked} elements");
    }
}
