//! `cargo xtask surface`: the public items of every library crate, counted
//! from the source (rustdoc's JSON, which would list them exactly, needs a
//! nightly compiler).
//!
//! The module tree is read from `src/lib.rs` with syn. A public item is
//! one declared `pub` (not `pub(crate)`, not under `#[cfg(test)]`) in a
//! module every ancestor of which is `pub`, or named by a `pub use` in such
//! a module; with it count its `pub` fields and the `pub` methods and
//! associated constants of its inherent impls. Enum variants and trait
//! methods belong to their enum or trait and are not counted apart; a
//! `pub use` of another crate's item counts as one re-export. Each item is
//! counted once however many paths reach it.
//!
//! `cargo xtask surface` prints the table docs/architecture.md holds;
//! `--check` (in CI) fails when the table there differs, so that a change
//! of a crate's public surface is a deliberate one, stated in the docs;
//! `--list CRATE` prints that crate's public items.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use syn::{Attribute, ImplItem, Item, UseTree, Visibility};

/// The document that states the counts, and the markers around its table.
const DOC: &str = "docs/architecture.md";
const BEGIN: &str = "<!-- surface:begin (cargo xtask surface) -->";
const END: &str = "<!-- surface:end -->";

/// One module of a crate: its path from the root, whether every ancestor
/// and itself are `pub`, and its parsed items.
struct Module {
    path: Vec<String>,
    public: bool,
    items: Vec<Item>,
}

/// Public items of one crate, by kind, and their names.
#[derive(Default)]
struct Surface {
    /// Kind → names (`module::Item`, `Type.field`, `Type::method`).
    kinds: BTreeMap<&'static str, BTreeSet<String>>,
    /// Public enums and structs marked `#[non_exhaustive]`, and all.
    non_exhaustive: usize,
    enums_structs: usize,
}

impl Surface {
    fn total(&self) -> usize {
        self.kinds.values().map(BTreeSet::len).sum()
    }
    fn count(&self, kind: &str) -> usize {
        self.kinds.get(kind).map_or(0, BTreeSet::len)
    }
}

/// The kinds of the table's columns, in order.
const KINDS: [&str; 6] = [
    "modules",
    "types",
    "functions",
    "constants",
    "fields",
    "methods",
];

/// `cargo xtask surface [--check | --list CRATE]`.
pub fn main(args: &[String]) -> Result<()> {
    let crates = library_crates()?;
    let mut surfaces = Vec::new();
    for dir in &crates {
        let name = dir
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        surfaces.push((name, surface(dir)?));
    }
    match args.first().map(String::as_str) {
        None => print!("{}", table(&surfaces)),
        Some("--list") => {
            let wanted = args.get(1).context("--list needs a crate name")?;
            let (_, s) = surfaces
                .iter()
                .find(|(n, _)| n == wanted)
                .with_context(|| format!("no library crate {wanted}"))?;
            for (kind, names) in &s.kinds {
                for name in names {
                    println!("{kind}\t{name}");
                }
            }
        }
        Some("--check") => check(&table(&surfaces))?,
        Some(other) => bail!("surface: unknown argument {other} (--check, --list CRATE)"),
    }
    Ok(())
}

/// Fails unless docs/architecture.md holds `expected` between the markers.
fn check(expected: &str) -> Result<()> {
    let doc = std::fs::read_to_string(DOC).with_context(|| format!("reading {DOC}"))?;
    let start = doc
        .find(BEGIN)
        .with_context(|| format!("{DOC}: no line {BEGIN}"))?
        + BEGIN.len();
    let end = doc[start..]
        .find(END)
        .with_context(|| format!("{DOC}: no line {END}"))?;
    if doc[start..start + end].trim() != expected.trim() {
        print!("{expected}");
        bail!(
            "{DOC}: the public-item table differs from the crates (above): \
             a public item was added or removed; update the table and say why"
        );
    }
    println!("surface: {DOC}'s public-item table matches the crates");
    Ok(())
}

/// The crates under crates/ with a `src/lib.rs`, sorted.
fn library_crates() -> Result<Vec<PathBuf>> {
    let mut crates: Vec<PathBuf> = std::fs::read_dir("crates")
        .context("run from the workspace root: no crates/ directory")?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("src/lib.rs").is_file())
        .collect();
    crates.sort();
    Ok(crates)
}

/// The Markdown table of every crate's counts.
fn table(surfaces: &[(String, Surface)]) -> String {
    let mut out = String::from("| crate | ");
    out.push_str(&KINDS.join(" | "));
    out.push_str(" | re-exports | total | non-exhaustive |\n|---|");
    out.push_str(&"---:|".repeat(KINDS.len() + 3));
    out.push('\n');
    for (name, s) in surfaces {
        out.push_str(&format!("| {name} |"));
        for kind in KINDS {
            out.push_str(&format!(" {} |", s.count(kind)));
        }
        out.push_str(&format!(
            " {} | {} | {} of {} |\n",
            s.count("re-exports"),
            s.total(),
            s.non_exhaustive,
            s.enums_structs
        ));
    }
    out
}

/// Reads the module tree of the crate in `dir` and counts its surface.
fn surface(dir: &Path) -> Result<Surface> {
    let mut modules = Vec::new();
    read_module(&dir.join("src/lib.rs"), Vec::new(), true, &mut modules)?;
    Ok(count(&modules))
}

/// The surface of a crate's modules.
fn count(modules: &[Module]) -> Surface {
    let mut exported = BTreeSet::new();
    let mut surface = Surface::default();
    for m in modules.iter().filter(|m| m.public) {
        for item in &m.items {
            if let Item::Use(u) = item
                && is_pub(&u.vis)
                && !is_test(&u.attrs)
            {
                let mut prefix = Vec::new();
                re_exports(
                    &m.path,
                    &u.tree,
                    &mut prefix,
                    modules,
                    &mut exported,
                    &mut surface,
                );
            }
        }
    }
    let public_types = count_items(modules, &exported, &mut surface);
    count_impls(modules, &public_types, &mut surface);
    surface
}

/// Parses the module file `file` and, recursively, its file modules.
fn read_module(file: &Path, path: Vec<String>, public: bool, out: &mut Vec<Module>) -> Result<()> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
    let parsed = syn::parse_file(&text).with_context(|| format!("parsing {}", file.display()))?;
    let dir = if file.ends_with("lib.rs") || file.ends_with("mod.rs") {
        file.parent().map(Path::to_path_buf).unwrap_or_default()
    } else {
        file.with_extension("")
    };
    collect_module(&dir, path, public, parsed.items, out)
}

/// Records one module's items and descends into its child modules.
fn collect_module(
    dir: &Path,
    path: Vec<String>,
    public: bool,
    mut items: Vec<Item>,
    out: &mut Vec<Module>,
) -> Result<()> {
    for item in &mut items {
        let Item::Mod(m) = item else { continue };
        if is_test(&m.attrs) {
            continue;
        }
        let mut child = path.clone();
        child.push(m.ident.to_string());
        let child_public = public && is_pub(&m.vis);
        let child_dir = dir.join(m.ident.to_string());
        if let Some((_, inline)) = m.content.take() {
            collect_module(&child_dir, child, child_public, inline, out)?;
        } else {
            let flat = dir.join(format!("{}.rs", m.ident));
            let file = if flat.is_file() {
                flat
            } else {
                child_dir.join("mod.rs")
            };
            read_module(&file, child, child_public, out)?;
        }
    }
    out.push(Module {
        path,
        public,
        items,
    });
    Ok(())
}

/// Resolves the names a `pub use` in module `at` exports: an item of this
/// crate is marked exported (a whole module: every `pub` item in it); a
/// name of another crate counts as a re-export.
fn re_exports(
    at: &[String],
    tree: &UseTree,
    prefix: &mut Vec<String>,
    modules: &[Module],
    exported: &mut BTreeSet<Vec<String>>,
    surface: &mut Surface,
) {
    match tree {
        UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            re_exports(at, &p.tree, prefix, modules, exported, surface);
            prefix.pop();
        }
        UseTree::Group(g) => {
            for t in &g.items {
                re_exports(at, t, prefix, modules, exported, surface);
            }
        }
        UseTree::Name(n) => export(at, prefix, &n.ident.to_string(), modules, exported, surface),
        UseTree::Rename(r) => export(at, prefix, &r.ident.to_string(), modules, exported, surface),
        UseTree::Glob(_) => {
            if let Some(module) = resolve(at, prefix, modules) {
                exported.insert(
                    module
                        .path
                        .iter()
                        .cloned()
                        .chain(["*".to_string()])
                        .collect(),
                );
            }
        }
    }
}

/// Marks `prefix::name` exported, or counts it as another crate's.
fn export(
    at: &[String],
    prefix: &[String],
    name: &str,
    modules: &[Module],
    exported: &mut BTreeSet<Vec<String>>,
    surface: &mut Surface,
) {
    match resolve(at, prefix, modules) {
        Some(module) => {
            let mut full = module.path.clone();
            full.push(name.to_string());
            // A module re-exported whole: everything `pub` in it.
            if modules.iter().any(|m| m.path == full) {
                surface.add("modules", full.join("::"));
                full.push("*".to_string());
            }
            exported.insert(full);
        }
        None => surface.add("re-exports", format!("{}::{}", prefix.join("::"), name)),
    }
}

/// The module of this crate that a `use` path's prefix names from module
/// `at` (`crate::`, `self::`, `super::` or a child), if it is one.
fn resolve<'m>(at: &[String], prefix: &[String], modules: &'m [Module]) -> Option<&'m Module> {
    let mut path: Vec<String> = at.to_vec();
    for (i, segment) in prefix.iter().enumerate() {
        match segment.as_str() {
            "crate" if i == 0 => path.clear(),
            "self" => {}
            "super" => {
                path.pop()?;
            }
            other => {
                path.push(other.to_string());
                modules.iter().find(|m| m.path == path)?;
            }
        }
    }
    modules.iter().find(|m| m.path == path)
}

impl Surface {
    fn add(&mut self, kind: &'static str, name: String) {
        self.kinds.entry(kind).or_default().insert(name);
    }
}

/// Counts the public items of every module (in a public module, or
/// exported); returns the public types by module path and name.
fn count_items(
    modules: &[Module],
    exported: &BTreeSet<Vec<String>>,
    surface: &mut Surface,
) -> BTreeSet<(Vec<String>, String)> {
    let mut types = BTreeSet::new();
    for m in modules {
        let mut glob = m.path.clone();
        glob.push("*".to_string());
        let whole = m.public || exported.contains(&glob);
        if m.public && !m.path.is_empty() {
            surface.add("modules", m.path.join("::"));
        }
        for item in &m.items {
            let Some((kind, name, attrs)) = public_item(item) else {
                continue;
            };
            let mut full = m.path.clone();
            full.push(name.clone());
            if !whole && !exported.contains(&full) {
                continue;
            }
            let shown = full.join("::");
            surface.add(kind, shown.clone());
            if kind == "types" {
                types.insert((m.path.clone(), name));
            }
            if matches!(item, Item::Struct(_) | Item::Enum(_)) {
                surface.enums_structs += 1;
                surface.non_exhaustive += usize::from(has_attr(attrs, "non_exhaustive"));
            }
            if let Item::Struct(s) = item {
                for field in s.fields.iter().filter(|f| is_pub(&f.vis)) {
                    if let Some(ident) = &field.ident {
                        surface.add("fields", format!("{shown}.{ident}"));
                    }
                }
            }
        }
    }
    types
}

/// The kind, name and attributes of an item declared `pub` (not in tests).
fn public_item(item: &Item) -> Option<(&'static str, String, &[Attribute])> {
    let (kind, vis, ident, attrs) = match item {
        Item::Struct(i) => ("types", &i.vis, &i.ident, &i.attrs),
        Item::Enum(i) => ("types", &i.vis, &i.ident, &i.attrs),
        Item::Union(i) => ("types", &i.vis, &i.ident, &i.attrs),
        Item::Trait(i) => ("types", &i.vis, &i.ident, &i.attrs),
        Item::Type(i) => ("types", &i.vis, &i.ident, &i.attrs),
        Item::Fn(i) => ("functions", &i.vis, &i.sig.ident, &i.attrs),
        Item::Const(i) => ("constants", &i.vis, &i.ident, &i.attrs),
        Item::Static(i) => ("constants", &i.vis, &i.ident, &i.attrs),
        Item::Macro(i) if has_attr(&i.attrs, "macro_export") => {
            return Some((
                "functions",
                i.ident.as_ref()?.to_string(),
                i.attrs.as_slice(),
            ));
        }
        _ => return None,
    };
    (is_pub(vis) && !is_test(attrs)).then(|| (kind, ident.to_string(), attrs.as_slice()))
}

/// Counts the `pub` methods and associated constants of the inherent
/// impls of public types (an impl names its type as the type's module
/// does, or from another module by the same name).
fn count_impls(modules: &[Module], types: &BTreeSet<(Vec<String>, String)>, surface: &mut Surface) {
    for m in modules {
        for item in &m.items {
            let Item::Impl(imp) = item else { continue };
            if imp.trait_.is_some() || is_test(&imp.attrs) {
                continue;
            }
            let syn::Type::Path(tp) = imp.self_ty.as_ref() else {
                continue;
            };
            let Some(last) = tp.path.segments.last() else {
                continue;
            };
            let name = last.ident.to_string();
            let owner = types
                .get(&(m.path.clone(), name.clone()))
                .or_else(|| types.iter().find(|(_, n)| *n == name));
            let Some((path, _)) = owner else { continue };
            let mut shown = path.clone();
            shown.push(name);
            let shown = shown.join("::");
            for member in &imp.items {
                let ident = match member {
                    ImplItem::Fn(f) if is_pub(&f.vis) && !is_test(&f.attrs) => &f.sig.ident,
                    ImplItem::Const(c) if is_pub(&c.vis) => &c.ident,
                    _ => continue,
                };
                surface.add("methods", format!("{shown}::{ident}"));
            }
        }
    }
}

fn is_pub(vis: &Visibility) -> bool {
    matches!(vis, Visibility::Public(_))
}

/// `#[cfg(test)]` (or any `cfg` naming `test`).
fn is_test(attrs: &[Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta.require_list().is_ok_and(|l| {
                l.tokens
                    .to_string()
                    .split(|c: char| !c.is_alphanumeric() && c != '_')
                    .any(|w| w == "test")
            })
    })
}

fn has_attr(attrs: &[Attribute], name: &str) -> bool {
    attrs.iter().any(|a| a.path().is_ident(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The surface of a crate given as its lib.rs text (inline modules).
    fn of(text: &str) -> Surface {
        let parsed = syn::parse_file(text).unwrap();
        let mut modules = Vec::new();
        let nowhere = Path::new("/nonexistent");
        collect_module(nowhere, Vec::new(), true, parsed.items, &mut modules).unwrap();
        count(&modules)
    }

    #[test]
    fn private_modules_count_only_what_is_re_exported() {
        let s = of("
            mod hidden { pub struct A { pub x: f64, y: f64 } pub struct B; pub fn f() {}
                         impl A { pub fn new() -> A { todo!() } fn private(&self) {} } }
            pub use hidden::A;
            pub use other_crate::Thing;
            pub mod open { pub enum E { X } #[non_exhaustive] pub struct S; pub(crate) fn g() {}
                           #[cfg(test)] pub fn only_in_tests() {} }
        ");
        let names = |k: &str| {
            s.kinds
                .get(k)
                .cloned()
                .unwrap_or_default()
                .into_iter()
                .collect::<Vec<_>>()
        };
        assert_eq!(names("types"), ["hidden::A", "open::E", "open::S"]);
        assert_eq!(names("fields"), ["hidden::A.x"]);
        assert_eq!(names("methods"), ["hidden::A::new"]);
        assert_eq!(names("functions"), Vec::<String>::new());
        assert_eq!(names("modules"), ["open"]);
        assert_eq!(names("re-exports"), ["other_crate::Thing"]);
        assert_eq!((s.non_exhaustive, s.enums_structs), (1, 3));
        assert_eq!(s.total(), 7);
    }

    #[test]
    fn an_item_reached_twice_counts_once_and_globs_export_a_module() {
        let s = of("
            pub mod a { pub fn f() {} }
            pub use a::f;
            mod b { pub fn g() {} pub fn h() {} }
            pub use self::b::*;
            mod c { pub fn k() {} }
            pub use crate::c as cc;
        ");
        let fns: Vec<_> = s.kinds["functions"].iter().cloned().collect();
        assert_eq!(fns, ["a::f", "b::g", "b::h", "c::k"]);
        assert_eq!(s.count("modules"), 2);
    }
}
