//! Stages 1 and 2 of loading: XML text → an intermediate tree with source
//! locations, `<default>` and `$name` substitution done.
//!
//! As in Mitsuba 3's parser, the tree knows nothing about plugins: it is just
//! elements and attributes, each with the line and column it came from. A
//! `<default name="n" value="v"/>` defines `$n` for the elements that follow it
//! (in document order), unless the caller already set `n`; every attribute
//! value has its `$name` references replaced. An undefined `$name` is an error,
//! as in Mitsuba.
//!
//! `<include filename="f.xml"/>` among `<scene>`'s children is replaced by
//! the children of `f.xml`'s own `<scene>` (Mitsuba 3), `f.xml` named
//! relative to the folder of the file that includes it. The included file
//! sees the `$name`s defined so far and its `<default>`s count for what
//! follows, as Mitsuba's parser shares them; elements keep the file they
//! came from in their locations.
//!
//! Bounded (`crate::limits`): the number of XML nodes, the nesting depth
//! (checked before each level is entered, so deep nesting is an error, not
//! a stack overflow), the length of each substituted value and the bytes
//! substitution produces over the whole file.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Result, SceneError, SourceLocation};
use crate::limits::{
    MAX_DEPTH, MAX_EXPANDED_BYTES, MAX_INCLUDED_BYTES, MAX_INCLUDES, MAX_VALUE_BYTES, MAX_XML_NODES,
};
use crate::text::Locator;

/// One attribute of an element, after substitution.
#[derive(Clone, Debug)]
pub(crate) struct Attribute {
    /// Attribute name.
    pub name: String,
    /// Value after `$name` substitution.
    pub value: String,
    /// Where the value starts.
    pub loc: SourceLocation,
}

/// One element of the intermediate tree.
#[derive(Clone, Debug)]
pub(crate) struct Element {
    /// Tag name (`shape`, `float`, ...).
    pub tag: String,
    /// Attributes in document order.
    pub attrs: Vec<Attribute>,
    /// Child elements (comments and whitespace dropped).
    pub children: Vec<Element>,
    /// Where the element starts.
    pub loc: SourceLocation,
}

impl Element {
    /// The attribute called `name`, if present.
    pub fn attr(&self, name: &str) -> Option<&Attribute> {
        self.attrs.iter().find(|a| a.name == name)
    }

    /// The attribute called `name`, or an error naming the element.
    pub fn required(&self, name: &str) -> Result<&Attribute> {
        self.attr(name).ok_or_else(|| {
            SceneError::at(
                &self.loc,
                format!("<{}> needs the attribute \"{name}\"", self.tag),
            )
        })
    }

    /// Refuses attributes outside `allowed`.
    pub fn check_attrs(&self, allowed: &[&str]) -> Result<()> {
        for a in &self.attrs {
            if !allowed.contains(&a.name.as_str()) {
                return Err(SceneError::at(
                    &a.loc,
                    format!("unexpected attribute \"{}\" in <{}>", a.name, self.tag),
                ));
            }
        }
        Ok(())
    }

    /// `type="..."` of a plugin element, or an error.
    pub fn plugin_type(&self) -> Result<&str> {
        Ok(self.required("type")?.value.as_str())
    }

    /// Description for messages: `<shape type="cube">`.
    pub fn describe(&self) -> String {
        match self.attr("type") {
            Some(t) => format!("<{} type=\"{}\">", self.tag, t.value),
            None => format!("<{}>", self.tag),
        }
    }
}

/// Parses scene text into the intermediate tree rooted at `<scene>`.
///
/// `params` are caller-given values for `$name` (they take precedence over
/// `<default>`s, as Mitsuba's `load_file(path, name=value)` does); one that
/// no `$name` of the scene (its included files too) uses is an error at the
/// `<scene>` element, as Mitsuba 3 refuses it ("Found unused parameters"):
/// a misspelt name must not be silently ignored.
pub(crate) fn parse(
    text: &str,
    file: &Arc<Path>,
    params: &[(String, String)],
) -> Result<(Element, Vec<PathBuf>)> {
    let (tree, shared) = parse_shared(text, file, params)?;
    Ok((tree, shared.files))
}

/// [`parse`], with what the files shared (the tests count its work).
fn parse_shared(
    text: &str,
    file: &Arc<Path>,
    params: &[(String, String)],
) -> Result<(Element, Shared)> {
    let mut shared = Shared {
        params: params.to_vec(),
        used: vec![false; params.len()],
        expanded: 0,
        chain: vec![file.clone()],
        included: 0,
        included_bytes: 0,
        files: Vec::new(),
        located_bytes: 0,
    };
    let tree = parse_file(text, file, &mut shared)?;
    if let Some(k) = shared.used.iter().position(|u| !u) {
        let (name, value) = &params[k];
        return Err(SceneError::at(
            &tree.loc,
            format!(
                "the parameter {name}={} is not used: the scene has no ${name} (Mitsuba refuses an unused parameter too)",
                crate::error::elide(value, 60)
            ),
        ));
    }
    Ok((tree, shared))
}

/// What the files of one scene share while they are parsed.
struct Shared {
    /// `$name` values: the caller's, then `<default>`s in document order.
    params: Vec<(String, String)>,
    /// Whether each caller's value (the first of `params`) was used.
    used: Vec<bool>,
    /// Bytes produced by `$name` substitution so far.
    expanded: usize,
    /// The files being parsed, the scene file first (include cycles).
    chain: Vec<Arc<Path>>,
    /// Files included so far, and their bytes.
    included: usize,
    included_bytes: u64,
    /// Every file included (outputs may not overwrite them).
    files: Vec<PathBuf>,
    /// Bytes read to find the lines and columns of elements and
    /// attributes, over every file: each file's length at most.
    located_bytes: usize,
}

/// Parses one file of the scene (the scene file or an included one).
fn parse_file(text: &str, file: &Arc<Path>, shared: &mut Shared) -> Result<Element> {
    let options = roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit: MAX_XML_NODES,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, options).map_err(|e| {
        let pos = e.pos();
        let loc = SourceLocation {
            file: file.clone(),
            line: pos.row,
            col: pos.col,
            pointer: None,
        };
        if matches!(e, roxmltree::Error::NodesLimitReached) {
            return SceneError::at(
                &loc,
                format!(
                    "the file has more than {MAX_XML_NODES} XML nodes, the limit (docs/limits.md)"
                ),
            );
        }
        // roxmltree repeats the position inside its message: drop it there.
        let message = e
            .to_string()
            .replace(&format!(" at {}:{}", pos.row, pos.col), "");
        SceneError::at(&loc, format!("malformed XML: {message}"))
    })?;
    let mut ctx = Context {
        file: file.clone(),
        locator: Locator::new(text),
        shared,
    };
    let root = doc.root_element();
    let root_loc = ctx.loc(root.range().start);
    if root.tag_name().name() != "scene" {
        return Err(SceneError::at(
            &root_loc,
            format!(
                "the root element must be <scene>, found <{}>",
                root.tag_name().name()
            ),
        ));
    }
    let tree = ctx
        .element(root, 1)?
        .pop()
        .ok_or_else(|| SceneError::at(&root_loc, "the root element must be <scene>"))?;
    ctx.shared.located_bytes += ctx.locator.scanned;
    check_version(&tree)?;
    Ok(tree)
}

/// Mitsuba requires `version="MAJOR.MINOR.PATCH"` on `<scene>`; files
/// older than 2.0 use other parameter names, which this loader does not
/// translate.
fn check_version(scene: &Element) -> Result<()> {
    let v = scene.attr("version").ok_or_else(|| {
        SceneError::at(
            &scene.loc,
            "<scene> needs a version attribute (version=\"3.0.0\")",
        )
    })?;
    let parts: Vec<Option<u32>> = v
        .value
        .split('.')
        .map(|p| {
            let digits = !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit());
            digits.then(|| p.parse().ok()).flatten()
        })
        .collect();
    match parts[..] {
        [Some(2 | 3), Some(_), Some(_)] => Ok(()),
        [Some(_), Some(_), Some(_)] => Err(SceneError::at(
            &v.loc,
            format!(
                "unsupported scene version \"{}\" (this loader reads Mitsuba 2 and 3 scenes)",
                v.value
            ),
        )),
        _ => Err(SceneError::at(
            &v.loc,
            format!(
                "malformed scene version \"{}\" (three numbers, as in version=\"3.0.0\")",
                v.value
            ),
        )),
    }
}

struct Context<'a, 'input> {
    file: Arc<Path>,
    /// Places in the file, asked in document order.
    locator: Locator<'input>,
    shared: &'a mut Shared,
}

impl Context<'_, '_> {
    fn loc(&mut self, byte: usize) -> SourceLocation {
        let (line, col) = self.locator.at(byte);
        SourceLocation {
            file: self.file.clone(),
            line,
            col,
            pointer: None,
        }
    }

    /// Converts one element at nesting `depth` (`<scene>` is 1): none for
    /// a `<default>`, which only defines a parameter, an included file's
    /// elements for an `<include>`, else the one element.
    fn element(&mut self, node: roxmltree::Node<'_, '_>, depth: usize) -> Result<Vec<Element>> {
        let loc = self.loc(node.range().start);
        if depth > MAX_DEPTH {
            return Err(SceneError::at(
                &loc,
                format!("elements nest more than {MAX_DEPTH} deep, the limit (docs/limits.md)"),
            ));
        }
        let tag = node.tag_name().name().to_string();
        let mut attrs = Vec::new();
        for a in node.attributes() {
            let aloc = self.loc(a.range_value().start);
            let value = self.substitute(a.value(), &aloc)?;
            attrs.push(Attribute {
                name: a.name().to_string(),
                value,
                loc: aloc,
            });
        }
        let element = Element {
            tag,
            attrs,
            children: Vec::new(),
            loc,
        };
        if element.tag == "default" {
            element.check_attrs(&["name", "value"])?;
            let name = element.required("name")?.value.clone();
            let value = element.required("value")?.value.clone();
            if node.children().any(|c| c.is_element()) {
                return Err(SceneError::at(&element.loc, "<default> has no children"));
            }
            if !self.shared.params.iter().any(|(n, _)| *n == name) {
                self.shared.params.push((name, value));
            }
            return Ok(Vec::new());
        }
        if element.tag == "include" {
            return self.include(&element, node, depth);
        }
        let mut element = element;
        for child in node.children() {
            if child.is_element() {
                element.children.extend(self.element(child, depth + 1)?);
            } else if child.is_text() {
                let text = child.text().unwrap_or("");
                if !text.trim().is_empty() {
                    return Err(SceneError::at(
                        &self.loc(child.range().start),
                        format!("unexpected text inside <{}>", element.tag),
                    ));
                }
            }
        }
        Ok(vec![element])
    }

    /// The elements of the file an `<include>` names (module docs).
    fn include(
        &mut self,
        e: &Element,
        node: roxmltree::Node<'_, '_>,
        depth: usize,
    ) -> Result<Vec<Element>> {
        e.check_attrs(&["filename"])?;
        if depth != 2 {
            return Err(SceneError::at(
                &e.loc,
                "<include> belongs directly in <scene>",
            ));
        }
        if node.children().any(|c| c.is_element()) {
            return Err(SceneError::at(&e.loc, "<include> has no children"));
        }
        let name = e.required("filename")?;
        let folder = self.file.parent().unwrap_or(Path::new(""));
        let path: Arc<Path> = Arc::from(folder.join(&name.value));
        let at = |m: String| SceneError::at(&name.loc, m);
        let same = |a: &Path| match (a.canonicalize(), path.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => a == &*path,
        };
        if self.shared.chain.iter().any(|f| same(f)) {
            let names: Vec<String> = self
                .shared
                .chain
                .iter()
                .chain(std::iter::once(&path))
                .map(|f| f.display().to_string())
                .collect();
            return Err(at(format!("include cycle: {}", names.join(" → "))));
        }
        self.shared.included += 1;
        if self.shared.included > MAX_INCLUDES {
            return Err(at(format!(
                "the scene includes more than {MAX_INCLUDES} files, the limit (docs/limits.md)"
            )));
        }
        let left = MAX_INCLUDED_BYTES - self.shared.included_bytes;
        let bytes = trilux_files::read_limited(&path, left).map_err(|source| {
            at(format!(
                "cannot read the included file {}: {source}",
                path.display()
            ))
        })?;
        self.shared.included_bytes += bytes.len() as u64;
        self.shared.files.push(path.to_path_buf());
        let text = crate::text::decode(&bytes, &path)?;
        self.shared.chain.push(path.clone());
        let tree = parse_file(text, &path, self.shared)?;
        self.shared.chain.pop();
        Ok(tree.children)
    }

    /// Replaces every `$name` in `value` by its parameter value, within
    /// the limits on one value and on the whole file.
    fn substitute(&mut self, value: &str, loc: &SourceLocation) -> Result<String> {
        if !value.contains('$') {
            return Ok(value.to_string());
        }
        let mut out = String::with_capacity(value.len());
        let mut rest = value;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..len];
            if name.is_empty() {
                return Err(SceneError::at(loc, "a lone '$' in an attribute value"));
            }
            match self.shared.params.iter().position(|(n, _)| n == name) {
                Some(k) => {
                    if let Some(used) = self.shared.used.get_mut(k) {
                        *used = true;
                    }
                    let v = &self.shared.params[k].1;
                    if out.len() + v.len() > MAX_VALUE_BYTES {
                        return Err(SceneError::at(
                            loc,
                            format!(
                                "the value grows beyond {} when ${name} is substituted, the limit (docs/limits.md)",
                                trilux_files::human_bytes(MAX_VALUE_BYTES as u64)
                            ),
                        ));
                    }
                    self.shared.expanded += v.len();
                    if self.shared.expanded > MAX_EXPANDED_BYTES {
                        return Err(SceneError::at(
                            loc,
                            format!(
                                "$name substitution produces more than {} over the file, the limit (docs/limits.md)",
                                trilux_files::human_bytes(MAX_EXPANDED_BYTES as u64)
                            ),
                        ));
                    }
                    out.push_str(v);
                }
                None => {
                    return Err(SceneError::at(
                        loc,
                        format!(
                            "undefined parameter ${name} (define it with <default name=\"{name}\" value=\"...\"/>)"
                        ),
                    ));
                }
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file() -> Arc<Path> {
        Arc::from(Path::new("t.xml"))
    }

    fn attr_value(text: &str, params: &[(&str, &str)]) -> Result<String> {
        let params: Vec<(String, String)> = params
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect();
        let (tree, _) = parse(text, &file(), &params)?;
        Ok(tree.children[0].attrs[0].value.clone())
    }

    #[test]
    fn substitution_replaces_whole_names_only() {
        let t = r#"<scene version="3.0.0"><a v="$x,$xy;$x_1"/></scene>"#;
        let v = attr_value(t, &[("x", "1"), ("xy", "2"), ("x_1", "3")]);
        assert_eq!(v.ok().as_deref(), Some("1,2;3"));
        let e = attr_value(t, &[("x", "1")]).expect_err("$xy undefined");
        assert!(e.to_string().contains("undefined parameter $xy"), "{e}");
        let e =
            attr_value(r#"<scene version="3.0.0"><a v="5$"/></scene>"#, &[]).expect_err("lone $");
        assert!(e.to_string().contains("lone '$'"), "{e}");
    }

    /// A caller's value that no `$name` uses is refused, as Mitsuba 3
    /// does, even when a `<default>` names it; at the `<scene>` element.
    #[test]
    fn an_unused_caller_value_is_refused() {
        let t = r#"<scene version="3.0.0"><default name="n" value="4"/><a v="$x"/></scene>"#;
        assert_eq!(attr_value(t, &[("x", "1")]).ok().as_deref(), Some("1"));
        for unused in ["n", "typo"] {
            let e = attr_value(t, &[("x", "1"), (unused, "2")]).expect_err("unused");
            let e = e.to_string();
            assert!(e.starts_with("t.xml:1:1: "), "{e}");
            assert!(e.contains(&format!("{unused}=2 is not used")), "{e}");
        }
    }

    #[test]
    fn defaults_apply_in_document_order_and_yield_to_callers() {
        let t = r#"<scene version="3.0.0"><default name="n" value="4"/><a v="$n"/></scene>"#;
        assert_eq!(attr_value(t, &[]).ok().as_deref(), Some("4"));
        assert_eq!(attr_value(t, &[("n", "9")]).ok().as_deref(), Some("9"));
        // A <default> after its use is too late, as in Mitsuba.
        let late = r#"<scene version="3.0.0"><a v="$n"/><default name="n" value="4"/></scene>"#;
        assert!(attr_value(late, &[]).is_err());
    }

    #[test]
    fn locations_are_one_based_line_and_column_of_values() {
        let t = "<scene version=\"3.0.0\">\n  <a\n     v=\"x\"/>\n</scene>";
        let (tree, _) = parse(t, &file(), &[]).unwrap_or_else(|e| panic!("{e}"));
        let a = &tree.children[0];
        assert_eq!((a.loc.line, a.loc.col), (2, 3));
        assert_eq!((a.attrs[0].loc.line, a.attrs[0].loc.col), (3, 9));
        assert_eq!((tree.loc.line, tree.loc.col), (1, 1));
    }

    #[test]
    fn comments_and_whitespace_are_dropped_text_is_refused() {
        let t = "<scene version=\"3.0.0\"> <!-- c --> <a/>\n</scene>";
        let (tree, _) = parse(t, &file(), &[]).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(tree.children.len(), 1);
        let e = parse("<scene version=\"3.0.0\">x</scene>", &file(), &[]).expect_err("text");
        assert!(
            e.to_string().starts_with("t.xml:1:24: unexpected text"),
            "{e}"
        );
    }

    /// Every element's and attribute's place is the one roxmltree's own
    /// `text_pos_at` gives (counting from the start of the file), with
    /// multi-byte characters, CR LF line ends and long lines.
    #[test]
    fn incremental_locations_match_counting_from_the_start() {
        let mut t = String::from("<scene version=\"3.0.0\">\r\n");
        for i in 0..40 {
            t += &format!("  <a é=\"ü{i}\"  b=\"{}\">", "x".repeat(i * 7));
            if i % 3 == 0 {
                t += "\r\n<!-- ∑ -->\n";
            }
            t += "<c d=\"1\"/></a>\n";
        }
        t += "</scene>";
        let doc = roxmltree::Document::parse(&t).unwrap_or_else(|e| panic!("{e}"));
        let (tree, _) = parse(&t, &file(), &[]).unwrap_or_else(|e| panic!("{e}"));
        let mut ours = Vec::new();
        let mut stack = vec![&tree];
        while let Some(e) = stack.pop() {
            ours.push((e.loc.line, e.loc.col));
            ours.extend(e.attrs.iter().map(|a| (a.loc.line, a.loc.col)));
            stack.extend(e.children.iter().rev());
        }
        let mut theirs = Vec::new();
        for n in doc.descendants().filter(|n| n.is_element()) {
            let p = doc.text_pos_at(n.range().start);
            theirs.push((p.row, p.col));
            for a in n.attributes() {
                let p = doc.text_pos_at(a.range_value().start);
                theirs.push((p.row, p.col));
            }
        }
        assert_eq!(ours.len(), 2 + 40 * 3 + 40 * 2);
        assert_eq!(ours, theirs);
    }

    /// Locating every element reads each byte of the file once: the work
    /// for 4n emitters is 4 times the work for n (it was quadratic: every
    /// element's line counted from the start of the file).
    #[test]
    fn locating_elements_reads_the_file_once() {
        let scene = |n: usize| {
            let mut t = String::from("<scene version=\"3.0.0\">\n");
            for i in 0..n {
                t += &format!(
                    "<shape type=\"rectangle\"><transform name=\"to_world\"><translate value=\"{i},0,0\"/></transform><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>\n"
                );
            }
            t + "</scene>"
        };
        let work = |n: usize| {
            let t = scene(n);
            let (tree, shared) = parse_shared(&t, &file(), &[]).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(tree.children.len(), n);
            assert!(
                shared.located_bytes <= t.len(),
                "{} > {}",
                shared.located_bytes,
                t.len()
            );
            shared.located_bytes as f64
        };
        let (small, large) = (work(2_500), work(10_000));
        let ratio = large / small;
        assert!((3.9..4.1).contains(&ratio), "work ×{ratio} for ×4 elements");
    }
}
