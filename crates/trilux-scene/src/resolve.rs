//! Stage 3 of loading: resolve `<ref id>` against the objects that carry an
//! `id` (top-level `<bsdf id>` in practice), and count `<bsdf>` elements.
//!
//! After this pass the tree has no `<ref>` left: each reference is replaced
//! by a copy of the element it names (BSDF parameters are plain data, so a
//! copy is as good as sharing). Only BSDFs can be referenced.

use std::collections::{BTreeMap, HashMap};

use crate::error::{Result, SceneError};
use crate::xml::Element;

/// The tree with references replaced, and how many `<bsdf>` elements of each
/// type the file holds (nested ones included, each written element once).
pub(crate) struct Resolved {
    /// The `<scene>` element, without `<ref>`s.
    pub scene: Element,
    /// `<bsdf>` type → number of `<bsdf>` elements written with it.
    pub bsdf_counts: BTreeMap<String, usize>,
}

/// Resolves references in `scene`.
pub(crate) fn resolve(scene: &Element) -> Result<Resolved> {
    let mut ids: HashMap<String, &Element> = HashMap::new();
    collect_ids(scene, &mut ids)?;
    let mut bsdf_counts = BTreeMap::new();
    count_bsdfs(scene, &mut bsdf_counts);
    let scene = substitute(scene, &ids, 0)?;
    Ok(Resolved { scene, bsdf_counts })
}

fn collect_ids<'a>(e: &'a Element, ids: &mut HashMap<String, &'a Element>) -> Result<()> {
    for child in &e.children {
        if child.tag != "ref"
            && let Some(id) = child.attr("id")
        {
            if let Some(first) = ids.get(&id.value) {
                return Err(SceneError::at(
                    &id.loc,
                    format!(
                        "id \"{}\" is already used by the {} at line {}",
                        id.value,
                        first.describe(),
                        first.loc.line
                    ),
                ));
            }
            ids.insert(id.value.clone(), child);
        }
        collect_ids(child, ids)?;
    }
    Ok(())
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

/// Copies `e`, replacing each `<ref>` by a resolved copy of its target.
fn substitute(e: &Element, ids: &HashMap<String, &Element>, depth: usize) -> Result<Element> {
    if depth > 64 {
        return Err(SceneError::at(
            &e.loc,
            "references nest too deeply (a reference cycle?)",
        ));
    }
    let mut out = Element {
        tag: e.tag.clone(),
        attrs: e.attrs.clone(),
        children: Vec::with_capacity(e.children.len()),
        loc: e.loc.clone(),
    };
    for child in &e.children {
        if child.tag == "ref" {
            child.check_attrs(&["id", "name"])?;
            let id = child.required("id")?;
            let target = ids.get(&id.value).ok_or_else(|| {
                SceneError::at(&id.loc, format!("reference to unknown id \"{}\"", id.value))
            })?;
            if target.tag != "bsdf" {
                return Err(SceneError::at(
                    &id.loc,
                    format!(
                        "\"{}\" names a {}; only <bsdf> elements can be referenced",
                        id.value,
                        target.describe()
                    ),
                ));
            }
            if !child.children.is_empty() {
                return Err(SceneError::at(&child.loc, "<ref> has no child elements"));
            }
            out.children.push(substitute(target, ids, depth + 1)?);
        } else {
            out.children.push(substitute(child, ids, depth + 1)?);
        }
    }
    Ok(out)
}
