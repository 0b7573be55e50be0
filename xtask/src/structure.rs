//! `cargo xtask structure`: the project's structural rules, checked on the
//! source text of every crate's `src/`.
//!
//! 1. **No module cycle inside a crate.** The nodes are a crate's top-level
//!    modules (a directory module with all its submodules is one node).
//!    There is an edge Y → X when a file of Y names `crate::X` (in a `use`,
//!    grouped or not, or in a path) or reaches X as `super::…::X` /
//!    `self::X`. The graph must be acyclic; so must the graph among the
//!    submodules of each directory module (same rule, one level down).
//! 2. **No file over [`MAX_FILE_LINES`] lines** in `crates/*/src`.
//! 3. **No function over [`MAX_FN_LINES`] lines**, counted from the line of
//!    its `fn` keyword to the line of its closing brace; the body is found
//!    by brace matching on a token stream that has already dropped
//!    comments, strings and character literals, so a `"{"` never counts.
//!
//! The check reads text, not the compiler's view: it knows modules by their
//! file layout (`a.rs`, `a/mod.rs`, `a/b.rs`) and inline `mod name { … }`
//! blocks, which is how every crate here is laid out (no `#[path]`).
//! Each offence is printed as `path:line: what`, then the longest function
//! and the largest file, so the margin is visible when nothing fails.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// The longest a file in `crates/*/src` may be, in lines.
pub const MAX_FILE_LINES: usize = 900;
/// The longest a function may be, in lines (its `fn` line to its `}` line).
pub const MAX_FN_LINES: usize = 100;

/// `cargo xtask structure`: checks every crate under `crates/`.
pub fn main() -> Result<()> {
    let mut crates: Vec<PathBuf> = std::fs::read_dir("crates")
        .context("run from the workspace root: no crates/ directory")?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("src").is_dir())
        .collect();
    crates.sort();
    let mut report = Report::default();
    for dir in &crates {
        let files = read_crate(&dir.join("src"))?;
        check_crate(&files, &mut report);
    }
    for offence in &report.offences {
        println!("{offence}");
    }
    if let Some((path, name, lines)) = &report.longest_fn {
        println!("longest function: {name} in {path}, {lines} lines (limit {MAX_FN_LINES})");
    }
    if let Some((path, lines)) = &report.largest_file {
        println!("largest file: {path}, {lines} lines (limit {MAX_FILE_LINES})");
    }
    if !report.offences.is_empty() {
        bail!("structure: {} offence(s)", report.offences.len());
    }
    println!("structure: no module cycle, no file or function over its limit");
    Ok(())
}

/// One source file of a crate: its path (as printed), its module path from
/// the crate root, and its text.
struct SourceFile {
    path: String,
    module: Vec<String>,
    text: String,
}

/// What the checks found across all crates.
#[derive(Default)]
struct Report {
    offences: Vec<String>,
    /// (path, function name, lines) of the longest function seen.
    longest_fn: Option<(String, String, usize)>,
    /// (path, lines) of the largest file seen.
    largest_file: Option<(String, usize)>,
}

/// Every `.rs` file under `src`, with the module path its place implies.
fn read_crate(src: &Path) -> Result<Vec<SourceFile>> {
    let mut files = Vec::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in
            std::fs::read_dir(&dir).with_context(|| format!("reading {}", dir.display()))?
        {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let relative = path.strip_prefix(src).unwrap_or(&path);
                let text = std::fs::read_to_string(&path)
                    .with_context(|| format!("reading {}", path.display()))?;
                files.push(SourceFile {
                    path: path.display().to_string(),
                    module: module_of(relative),
                    text,
                });
            }
        }
    }
    files.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(files)
}

/// The module path a file's place under `src/` implies: `lib.rs`/`main.rs`
/// are the root, `a/mod.rs` and `a.rs` are `a`, `a/b.rs` is `a::b`.
/// (Files under `src/bin/` are roots of their own binaries: `[]` too.)
fn module_of(relative: &Path) -> Vec<String> {
    let parts: Vec<String> = relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.first().is_some_and(|p| p == "bin") {
        return Vec::new();
    }
    let mut module: Vec<String> = parts
        .iter()
        .map(|p| p.trim_end_matches(".rs").to_string())
        .collect();
    if module.len() == 1 && (module[0] == "lib" || module[0] == "main") {
        return Vec::new();
    }
    if module.last().is_some_and(|m| m == "mod") {
        module.pop();
    }
    module
}

/// Runs the three checks on one crate's files.
fn check_crate(files: &[SourceFile], report: &mut Report) {
    let mut references = Vec::new();
    let mut test_only: Vec<Vec<String>> = Vec::new();
    for file in files {
        let lines = file.text.lines().count();
        if lines > MAX_FILE_LINES {
            report.offences.push(format!(
                "{}:1: file has {lines} lines (limit {MAX_FILE_LINES})",
                file.path
            ));
        }
        if report.largest_file.as_ref().is_none_or(|(_, n)| lines > *n) {
            report.largest_file = Some((file.path.clone(), lines));
        }
        let tokens = tokenize(&file.text);
        for f in functions(&tokens) {
            if f.lines > MAX_FN_LINES {
                report.offences.push(format!(
                    "{}:{}: fn {} has {} lines (limit {MAX_FN_LINES})",
                    file.path, f.line, f.name, f.lines
                ));
            }
            if report
                .longest_fn
                .as_ref()
                .is_none_or(|(_, _, n)| f.lines > *n)
            {
                report.longest_fn = Some((file.path.clone(), f.name.clone(), f.lines));
            }
        }
        let (production, test_modules) = without_test_code(&tokens);
        test_only.extend(test_modules.into_iter().map(|name| {
            let mut m = file.module.clone();
            m.push(name);
            m
        }));
        for r in module_references(&production, &file.module) {
            references.push((file, r));
        }
    }
    // A test module may build on any part of its crate: only the code that
    // ships counts towards the module graph.
    references.retain(|(f, _)| !test_only.iter().any(|m| f.module.starts_with(m)));
    report.offences.extend(cycles(files, &references));
}

/// The token stream without the items marked `#[cfg(test)]` (an inline
/// `mod tests { … }`, a test-only function, a `mod name;` declaration),
/// and the names of the test-only modules declared in other files.
fn without_test_code(tokens: &[(Token, usize)]) -> (Vec<(Token, usize)>, Vec<String>) {
    let ident = |t: &Token, w: &str| matches!(t, Token::Ident(x) if x == w);
    let is_cfg_test = |k: usize| {
        let want = ["#", "[", "cfg", "(", "test", ")", "]"];
        want.iter().enumerate().all(|(i, w)| {
            tokens.get(k + i).is_some_and(|(t, _)| match t {
                Token::Punct(c) => c.to_string() == *w,
                Token::Ident(x) => x == w,
                Token::PathSep => false,
            })
        })
    };
    let (mut kept, mut test_modules) = (Vec::new(), Vec::new());
    let mut k = 0;
    while k < tokens.len() {
        if !is_cfg_test(k) {
            kept.push(tokens[k].clone());
            k += 1;
            continue;
        }
        // Skip the attribute, then the item: to its `;` or its body's end.
        let mut j = k + 7;
        while j < tokens.len() && !matches!(tokens[j].0, Token::Punct(';' | '{')) {
            j += 1;
        }
        if tokens.get(j).is_some_and(|(t, _)| *t == Token::Punct(';')) {
            if let (Some((m, _)), Some((Token::Ident(name), _))) =
                (tokens.get(j.wrapping_sub(2)), tokens.get(j.wrapping_sub(1)))
                && ident(m, "mod")
            {
                test_modules.push(name.clone());
            }
            k = j + 1;
        } else {
            k = matching_brace(tokens, j).map_or(tokens.len(), |e| e + 1);
        }
    }
    (kept, test_modules)
}

/// The module cycles among siblings, for every directory module (and the
/// crate root), reported edge by edge.
fn cycles(files: &[SourceFile], references: &[(&SourceFile, Reference)]) -> Vec<String> {
    // Every module that has a file, and its parents: these are the nodes.
    let mut modules: BTreeSet<Vec<String>> = BTreeSet::new();
    for f in files {
        for depth in 0..=f.module.len() {
            modules.insert(f.module[..depth].to_vec());
        }
    }
    let mut offences = Vec::new();
    for parent in &modules {
        let children: BTreeSet<&String> = modules
            .iter()
            .filter(|m| m.len() == parent.len() + 1 && m.starts_with(parent))
            .map(|m| &m[parent.len()])
            .collect();
        if children.len() < 2 {
            continue;
        }
        // Edge Y → X with the first place it is named.
        let mut edges: BTreeMap<(String, String), (String, usize)> = BTreeMap::new();
        for (file, r) in references {
            let (Some(from), Some(to)) = (
                child_under(parent, &r.from, &children),
                child_under(parent, &r.target, &children),
            ) else {
                continue;
            };
            if from != to {
                edges
                    .entry((from, to))
                    .or_insert_with(|| (file.path.clone(), r.line));
            }
        }
        for component in strongly_connected(&children, &edges) {
            let members = component.iter().cloned().collect::<Vec<_>>().join(", ");
            let scope = if parent.is_empty() {
                "crate".to_string()
            } else {
                format!("crate::{}", parent.join("::"))
            };
            for ((from, to), (path, line)) in &edges {
                if component.contains(from) && component.contains(to) {
                    offences.push(format!(
                        "{path}:{line}: module cycle in {scope} {{{members}}}: {from} names {to}"
                    ));
                }
            }
        }
    }
    offences
}

/// The child of `parent` that `module` lies in, if it is one of `children`.
fn child_under(
    parent: &[String],
    module: &[String],
    children: &BTreeSet<&String>,
) -> Option<String> {
    if module.len() > parent.len()
        && module.starts_with(parent)
        && children.contains(&module[parent.len()])
    {
        Some(module[parent.len()].clone())
    } else {
        None
    }
}

/// The strongly connected components with more than one node (Tarjan).
fn strongly_connected(
    nodes: &BTreeSet<&String>,
    edges: &BTreeMap<(String, String), (String, usize)>,
) -> Vec<BTreeSet<String>> {
    struct Tarjan<'a> {
        next: BTreeMap<&'a str, Vec<&'a str>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        found: Vec<BTreeSet<String>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a str) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.next.get(v).cloned().unwrap_or_default() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.low[v].min(self.low[w]);
                    self.low.insert(v, low);
                } else if self.on_stack.contains(w) {
                    let low = self.low[v].min(self.index[w]);
                    self.low.insert(v, low);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = BTreeSet::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    component.insert(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    self.found.push(component);
                }
            }
        }
    }
    let mut next: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for (from, to) in edges.keys() {
        next.entry(from.as_str()).or_default().push(to.as_str());
    }
    let mut t = Tarjan {
        next,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for v in nodes {
        if !t.index.contains_key(v.as_str()) {
            t.visit(v);
        }
    }
    t.found
}

/// A token of Rust source with comments, strings and characters dropped.
#[derive(Debug, Clone, PartialEq)]
enum Token {
    /// An identifier or keyword (raw identifiers without their `r#`).
    Ident(String),
    /// `::`
    PathSep,
    /// Any other punctuation character.
    Punct(char),
}

/// Splits source text into [`Token`]s with their 1-based line numbers.
/// Comments (nested block comments too), string literals (escaped, raw,
/// byte), character literals and numbers are skipped; lifetimes are
/// skipped as well (a `'` not closing a character literal).
fn tokenize(text: &str) -> Vec<(Token, usize)> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut line = 1;
    let mut i = 0;
    let at = |k: usize| chars.get(k).copied().unwrap_or('\0');
    while i < chars.len() {
        let c = chars[i];
        let start_line = line;
        if c == '\n' {
            line += 1;
            i += 1;
        } else if c.is_whitespace() {
            i += 1;
        } else if c == '/' && at(i + 1) == '/' {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            while i < chars.len() {
                if chars[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if chars[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    if chars[i] == '\n' {
                        line += 1;
                    }
                    i += 1;
                }
            }
        } else if let Some(end) = raw_string_end(&chars, i) {
            line += chars[i..end].iter().filter(|&&c| c == '\n').count();
            i = end;
        } else if c == '"' || (c == 'b' && at(i + 1) == '"') || (c == 'c' && at(i + 1) == '"') {
            i += if c == '"' { 1 } else { 2 };
            while i < chars.len() && chars[i] != '"' {
                if chars[i] == '\\' {
                    i += 1;
                }
                if at(i) == '\n' {
                    line += 1;
                }
                i += 1;
            }
            i += 1;
        } else if c == '\'' || (c == 'b' && at(i + 1) == '\'') {
            let q = if c == '\'' { i } else { i + 1 };
            if at(q + 1) == '\\' {
                // An escaped character literal: skip the backslash and the
                // escaped character, then to the closing quote.
                i = q + 3;
                while i < chars.len() && chars[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if at(q + 2) == '\'' {
                i = q + 3;
            } else {
                // A lifetime or label: skip the quote, the name follows.
                i = q + 1;
            }
        } else if c.is_alphabetic() || c == '_' {
            let mut j = i;
            if c == 'r' && at(i + 1) == '#' && (at(i + 2).is_alphabetic() || at(i + 2) == '_') {
                j = i + 2;
            }
            let begin = j;
            while j < chars.len() && (chars[j].is_alphanumeric() || chars[j] == '_') {
                j += 1;
            }
            tokens.push((Token::Ident(chars[begin..j].iter().collect()), start_line));
            i = j;
        } else if c.is_ascii_digit() {
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
        } else if c == ':' && at(i + 1) == ':' {
            tokens.push((Token::PathSep, start_line));
            i += 2;
        } else {
            tokens.push((Token::Punct(c), start_line));
            i += 1;
        }
    }
    tokens
}

/// If a raw string literal (`r"…"`, `r#"…"#`, `br#"…"#`, `cr"…"`) starts
/// at `i`, the index just past its end.
fn raw_string_end(chars: &[char], i: usize) -> Option<usize> {
    let mut j = i;
    if matches!(chars.get(j), Some('b' | 'c')) {
        j += 1;
    }
    if chars.get(j) != Some(&'r') {
        return None;
    }
    // An identifier that merely ends in `r` (e.g. `bar"`) is not a prefix.
    if i > 0
        && chars
            .get(i - 1)
            .is_some_and(|c| c.is_alphanumeric() || *c == '_')
    {
        return None;
    }
    j += 1;
    let mut hashes = 0;
    while chars.get(j) == Some(&'#') {
        hashes += 1;
        j += 1;
    }
    if chars.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < chars.len() {
        if chars[j] == '"' && (1..=hashes).all(|k| chars.get(j + k) == Some(&'#')) {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(chars.len())
}

/// A function item found in a token stream.
#[derive(Debug)]
struct Function {
    name: String,
    /// Line of the `fn` keyword.
    line: usize,
    /// From the `fn` line to the closing brace's line, inclusive.
    lines: usize,
}

/// Every `fn name … { … }` in the stream (declarations without a body,
/// `fn(…)` pointer types and `Fn` bounds are not functions).
fn functions(tokens: &[(Token, usize)]) -> Vec<Function> {
    let mut found = Vec::new();
    for (k, (token, line)) in tokens.iter().enumerate() {
        if *token != Token::Ident("fn".into()) {
            continue;
        }
        let Some((Token::Ident(name), _)) = tokens.get(k + 1) else {
            continue;
        };
        // The body is the first `{` outside the signature's () and [].
        let mut depth = 0i32;
        let mut open = None;
        for (j, (t, _)) in tokens.iter().enumerate().skip(k + 2) {
            match t {
                Token::Punct('(' | '[') => depth += 1,
                Token::Punct(')' | ']') => depth -= 1,
                Token::Punct('{') if depth == 0 => {
                    open = Some(j);
                    break;
                }
                Token::Punct(';') if depth == 0 => break,
                _ => {}
            }
        }
        let Some(open) = open else { continue };
        if let Some(close) = matching_brace(tokens, open) {
            found.push(Function {
                name: name.clone(),
                line: *line,
                lines: tokens[close].1 - line + 1,
            });
        }
    }
    found
}

/// The index of the `}` closing the `{` at `open`.
fn matching_brace(tokens: &[(Token, usize)], open: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (j, (t, _)) in tokens.iter().enumerate().skip(open) {
        match t {
            Token::Punct('{') => depth += 1,
            Token::Punct('}') => {
                depth -= 1;
                if depth == 0 {
                    return Some(j);
                }
            }
            _ => {}
        }
    }
    None
}

/// A path that names a module of the same crate.
#[derive(Debug, PartialEq)]
struct Reference {
    /// The module whose code names it (inline `mod` blocks included).
    from: Vec<String>,
    /// The path it names, resolved from the crate root (it may go on to
    /// name an item inside the module: only its prefix matters).
    target: Vec<String>,
    line: usize,
}

/// Every `crate::…`, `super::…` and `self::…` path in the stream,
/// resolved against the module it is written in; grouped `use` trees
/// (`use crate::{a, b::{c, d}}`) give one reference per leaf.
fn module_references(tokens: &[(Token, usize)], file_module: &[String]) -> Vec<Reference> {
    let mut found = Vec::new();
    // Inline `mod name {` blocks: (name, brace depth inside the block).
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut depth = 0usize;
    let mut k = 0;
    while k < tokens.len() {
        let module = || {
            let mut m = file_module.to_vec();
            m.extend(inline.iter().map(|(n, _)| n.clone()));
            m
        };
        match &tokens[k].0 {
            Token::Punct('{') => depth += 1,
            Token::Punct('}') => {
                if inline.last().is_some_and(|(_, d)| *d == depth) {
                    inline.pop();
                }
                depth = depth.saturating_sub(1);
            }
            Token::Ident(word) if word == "mod" => {
                if let (Some((Token::Ident(name), _)), Some((Token::Punct('{'), _))) =
                    (tokens.get(k + 1), tokens.get(k + 2))
                {
                    depth += 1;
                    inline.push((name.clone(), depth));
                    k += 3;
                    continue;
                }
            }
            Token::Ident(word)
                if matches!(word.as_str(), "crate" | "super" | "self")
                    && tokens.get(k + 1).is_some_and(|(t, _)| *t == Token::PathSep)
                    // `a::self` / `a::super` continue a path, not start one.
                    && !(k > 0 && tokens[k - 1].0 == Token::PathSep) =>
            {
                let here = module();
                let mut base = match word.as_str() {
                    "crate" => Vec::new(),
                    _ => here.clone(),
                };
                let mut j = k;
                if word == "super" {
                    base.pop();
                }
                j += 2;
                // Further `super::` steps.
                while let (Some((Token::Ident(w), _)), Some((Token::PathSep, _))) =
                    (tokens.get(j), tokens.get(j + 1))
                {
                    if w != "super" {
                        break;
                    }
                    base.pop();
                    j += 2;
                }
                let line = tokens[k].1;
                let mut leaves = Vec::new();
                let end = use_tree(tokens, j, base, &mut leaves);
                found.extend(leaves.into_iter().map(|target| Reference {
                    from: here.clone(),
                    target,
                    line,
                }));
                k = end.max(k + 1);
                continue;
            }
            _ => {}
        }
        k += 1;
    }
    found
}

/// Parses a path or use tree starting at `j` below `prefix`, pushing each
/// leaf path; returns the index after it.
fn use_tree(
    tokens: &[(Token, usize)],
    mut j: usize,
    mut prefix: Vec<String>,
    leaves: &mut Vec<Vec<String>>,
) -> usize {
    loop {
        match tokens.get(j).map(|(t, _)| t) {
            Some(Token::Ident(name)) => {
                if name != "self" {
                    prefix.push(name.clone());
                }
                j += 1;
                if tokens.get(j).is_some_and(|(t, _)| *t == Token::PathSep) {
                    j += 1;
                    continue;
                }
                leaves.push(prefix);
                return j;
            }
            Some(Token::Punct('{')) => {
                j += 1;
                loop {
                    match tokens.get(j).map(|(t, _)| t) {
                        Some(Token::Punct('}')) | None => return j + 1,
                        Some(Token::Punct(',')) => j += 1,
                        Some(Token::Ident(_)) | Some(Token::Punct('{')) => {
                            j = use_tree(tokens, j, prefix.clone(), leaves);
                            // `a as b`: skip the alias.
                            if let Some((Token::Ident(w), _)) = tokens.get(j)
                                && w == "as"
                            {
                                j += 2;
                            }
                        }
                        Some(_) => j += 1,
                    }
                }
            }
            // `crate::*`, `super::*` or a path ending in a glob or generic.
            _ => {
                leaves.push(prefix);
                return j;
            }
        }
    }
}

/// A one-line summary of a token stream's module references, for tests.
#[cfg(test)]
fn describe(references: &[Reference]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    for r in references {
        let _ = writeln!(
            s,
            "{} -> {} @{}",
            r.from.join("::"),
            r.target.join("::"),
            r.line
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(path: &str, module: &[&str], text: &str) -> SourceFile {
        SourceFile {
            path: path.to_string(),
            module: module.iter().map(|m| m.to_string()).collect(),
            text: text.to_string(),
        }
    }

    fn check(files: &[SourceFile]) -> Report {
        let mut report = Report::default();
        check_crate(files, &mut report);
        report
    }

    #[test]
    fn module_paths_follow_the_file_layout() {
        assert_eq!(module_of(Path::new("lib.rs")), Vec::<String>::new());
        assert_eq!(module_of(Path::new("a.rs")), vec!["a"]);
        assert_eq!(module_of(Path::new("a/mod.rs")), vec!["a"]);
        assert_eq!(module_of(Path::new("a/b.rs")), vec!["a", "b"]);
    }

    #[test]
    fn a_grouped_use_gives_one_reference_per_leaf() {
        let text = "use crate::{a, b::{c, d as e}, f::G};\nfn x() { crate::h::y(); }";
        let refs = module_references(&tokenize(text), &["m".to_string()]);
        assert_eq!(
            describe(&refs),
            "m -> a @1\nm -> b::c @1\nm -> b::d @1\nm -> f::G @1\nm -> h::y @2\n"
        );
    }

    #[test]
    fn super_and_inline_modules_resolve_against_where_they_are_written() {
        let text = "use super::x::Y;\nmod tests {\n use super::Z;\n use super::super::w;\n}\nuse self::q::R;";
        let refs = module_references(&tokenize(text), &["a".to_string(), "b".to_string()]);
        assert_eq!(
            describe(&refs),
            "a::b -> a::x::Y @1\na::b::tests -> a::b::Z @3\na::b::tests -> a::w @4\na::b -> a::b::q::R @6\n"
        );
    }

    #[test]
    fn a_cycle_between_top_level_modules_is_found() {
        let files = [
            file("src/lib.rs", &[], "mod a; mod b; mod c;"),
            file("src/a.rs", &["a"], "use crate::b::B;"),
            file("src/b/mod.rs", &["b"], "mod inner;"),
            // A submodule of b reaching a through `super::super`.
            file(
                "src/b/inner.rs",
                &["b", "inner"],
                "fn f() { super::super::a::g(); }",
            ),
            file("src/c.rs", &["c"], "use crate::{a, b};"),
        ];
        let report = check(&files);
        assert_eq!(report.offences.len(), 2, "{:?}", report.offences);
        assert!(
            report.offences[0].starts_with("src/a.rs:1: module cycle in crate {a, b}: a names b")
        );
        assert!(
            report.offences[1]
                .starts_with("src/b/inner.rs:1: module cycle in crate {a, b}: b names a")
        );
    }

    #[test]
    fn an_acyclic_crate_and_a_cycle_among_submodules() {
        let acyclic = [
            file("src/a.rs", &["a"], "use crate::b::B;"),
            file("src/b.rs", &["b"], "use crate::c::{self, C};"),
            file("src/c.rs", &["c"], "pub struct C;"),
        ];
        assert!(check(&acyclic).offences.is_empty());
        let nested = [
            file("src/d/mod.rs", &["d"], "mod x; mod y;"),
            file("src/d/x.rs", &["d", "x"], "use super::y::Y;"),
            file("src/d/y.rs", &["d", "y"], "use crate::d::x::X;"),
        ];
        let offences = check(&nested).offences;
        assert_eq!(offences.len(), 2, "{offences:?}");
        assert!(offences[0].contains("module cycle in crate::d {x, y}"));
    }

    #[test]
    fn test_code_does_not_count_towards_the_module_graph() {
        let files = vec![
            file(
                "src/lib.rs",
                &[],
                "mod a; mod b;\n#[cfg(test)]\nmod fixtures;",
            ),
            file("src/a.rs", &["a"], "use crate::b::X;"),
            file(
                "src/b.rs",
                &["b"],
                "pub struct X;\n#[cfg(test)]\nmod tests {\n use crate::a::f;\n}",
            ),
            file(
                "src/fixtures.rs",
                &["fixtures"],
                "use crate::a::f; use crate::b::X;",
            ),
        ];
        assert!(check(&files).offences.is_empty());
        // The same reference outside a test module is a cycle.
        let files = vec![
            file("src/lib.rs", &[], "mod a; mod b;"),
            file("src/a.rs", &["a"], "use crate::b::X;"),
            file(
                "src/b.rs",
                &["b"],
                "pub struct X;\nmod tests {\n use crate::a::f;\n}",
            ),
        ];
        assert_eq!(check(&files).offences.len(), 2);
    }

    #[test]
    fn a_long_function_is_found_and_measured_from_fn_to_brace() {
        let body = "    let x = 1;\n".repeat(MAX_FN_LINES - 1);
        let text = format!(
            "/// doc\n#[inline]\nfn long() {{\n{body}}}\nfn short(a: [u8; 3]) -> u8 {{ a[0] }}\n"
        );
        let fns = functions(&tokenize(&text));
        assert_eq!(fns.len(), 2);
        assert_eq!(
            (fns[0].name.as_str(), fns[0].line, fns[0].lines),
            ("long", 3, MAX_FN_LINES + 1)
        );
        assert_eq!((fns[1].name.as_str(), fns[1].lines), ("short", 1));
        let report = check(&[file("src/l.rs", &["l"], &text)]);
        assert_eq!(
            report.offences,
            vec![format!(
                "src/l.rs:3: fn long has {} lines (limit {MAX_FN_LINES})",
                MAX_FN_LINES + 1
            )]
        );
    }

    #[test]
    fn braces_in_strings_chars_and_comments_are_ignored() {
        let text = r##"fn a<'a>(s: &'a str) -> char {
    let _ = "}}} {";
    let _ = r#"}"{"#;
    let _ = b"}";
    // }
    /* } /* nested } */ } */
    if s == "\"}" { '}' } else { '\'' }
}
fn b() {}
fn decl(x: fn(u8) -> u8);
"##;
        let fns = functions(&tokenize(text));
        let found: Vec<_> = fns
            .iter()
            .map(|f| (f.name.as_str(), f.line, f.lines))
            .collect();
        assert_eq!(found, vec![("a", 1, 8), ("b", 9, 1)]);
    }

    #[test]
    fn a_file_over_the_limit_is_reported() {
        let text = "\n".repeat(MAX_FILE_LINES + 1);
        let report = check(&[file("src/big.rs", &["big"], &text)]);
        assert_eq!(report.offences.len(), 1);
        assert!(report.offences[0].starts_with("src/big.rs:1: file has 901 lines"));
    }
}
