//! Stage 3 of loading: resolve `<ref id>` against the objects that carry an
//! `id` (top-level `<bsdf id>` in practice), and count `<bsdf>` elements.
//!
//! After this pass the tree has no `<ref>` left: each reference is replaced
//! by a copy of the element it names (BSDF parameters are plain data, so a
//! copy is as good as sharing). Only BSDFs can be referenced.
//!
//! A reference to a BSDF that is being expanded is a cycle, refused as
//! one; the expanded tree is bounded in depth and in size
//! (`crate::limits`), since references can nest and multiply.

use std::collections::{BTreeMap, HashMap};

use crate::error::{Result, SceneError};
use crate::limits::{MAX_DEPTH, MAX_ELEMENTS};
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
    let mut expander = Expander {
        ids: &ids,
        elements: 0,
        expanding: Vec::new(),
    };
    let scene = expander.substitute(scene, 1)?;
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

/// The state of the expansion of references.
struct Expander<'a> {
    ids: &'a HashMap<String, &'a Element>,
    /// Elements made so far.
    elements: usize,
    /// The ids of the elements being copied, outermost first.
    expanding: Vec<&'a str>,
}

impl<'a> Expander<'a> {
    /// Copies `e` (at nesting `depth`, `<scene>` being 1), replacing each
    /// `<ref>` by a resolved copy of its target.
    fn substitute(&mut self, e: &'a Element, depth: usize) -> Result<Element> {
        if depth > MAX_DEPTH {
            return Err(SceneError::at(
                &e.loc,
                format!(
                    "elements nest more than {MAX_DEPTH} deep once references are expanded, the limit (docs/limits.md)"
                ),
            ));
        }
        self.elements += 1;
        if self.elements > MAX_ELEMENTS {
            return Err(SceneError::at(
                &e.loc,
                format!(
                    "references expand the scene to more than {MAX_ELEMENTS} elements, the limit (docs/limits.md)"
                ),
            ));
        }
        let mut out = Element {
            tag: e.tag.clone(),
            attrs: e.attrs.clone(),
            children: Vec::with_capacity(e.children.len()),
            loc: e.loc.clone(),
        };
        let id = e.attr("id").map(|a| a.value.as_str());
        self.expanding.extend(id);
        for child in &e.children {
            let copy = if child.tag == "ref" {
                self.reference(child, depth)?
            } else {
                self.substitute(child, depth + 1)?
            };
            out.children.push(copy);
        }
        if id.is_some() {
            self.expanding.pop();
        }
        Ok(out)
    }

    /// The resolved copy of what `<ref>` element `r` names.
    fn reference(&mut self, r: &'a Element, depth: usize) -> Result<Element> {
        r.check_attrs(&["id", "name"])?;
        let id = r.required("id")?;
        let (name, target) = self.ids.get_key_value(&id.value).ok_or_else(|| {
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
        if !r.children.is_empty() {
            return Err(SceneError::at(&r.loc, "<ref> has no child elements"));
        }
        if self.expanding.contains(&name.as_str()) {
            let mut chain = self.expanding.clone();
            chain.push(name);
            let start = chain.iter().position(|n| *n == name.as_str()).unwrap_or(0);
            return Err(SceneError::at(
                &id.loc,
                format!("reference cycle: {}", chain[start..].join(" → ")),
            ));
        }
        self.substitute(target, depth + 1)
    }
}
