//! Numbers as scene files write them: one finite number, lists separated
//! by commas and/or whitespace (as Mitsuba reads them), and 3-vectors.
//! Every number must be finite: `nan` and `inf` are refused here, once, so
//! that nothing downstream sees them. A leaf: typed values (`value`) and
//! transforms ([`crate::transform`]) both read their numbers here.

use glam::DVec3;

use crate::error::{Result, SceneError, SourceLocation};
use crate::xml::Element;

/// Parses one finite number.
pub(crate) fn parse_f64(text: &str, loc: &SourceLocation) -> Result<f64> {
    let t = text.trim();
    let v: f64 = t
        .parse()
        .map_err(|_| SceneError::at(loc, format!("\"{t}\" is not a number")))?;
    if v.is_nan() {
        return Err(SceneError::at(loc, "NaN is not allowed here"));
    }
    if !v.is_finite() {
        return Err(SceneError::at(
            loc,
            format!("\"{t}\" is not a finite number"),
        ));
    }
    Ok(v)
}

/// Parses a list of finite numbers separated by commas and/or whitespace.
pub(crate) fn parse_list(text: &str, loc: &SourceLocation) -> Result<Vec<f64>> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| parse_f64(t, loc))
        .collect()
}

/// Parses exactly `n` numbers.
pub(crate) fn parse_n(text: &str, n: usize, loc: &SourceLocation) -> Result<Vec<f64>> {
    let v = parse_list(text, loc)?;
    if v.len() != n {
        return Err(SceneError::at(
            loc,
            format!("expected {n} numbers, found {} in \"{text}\"", v.len()),
        ));
    }
    Ok(v)
}

/// A 3-vector written as `value="x, y, z"` or with `x`, `y`, `z` attributes
/// (each defaulting to `default`).
pub(crate) fn parse_xyz(e: &Element, default: f64) -> Result<DVec3> {
    if let Some(v) = e.attr("value") {
        if ["x", "y", "z"].iter().any(|n| e.attr(n).is_some()) {
            return Err(SceneError::at(
                &v.loc,
                format!("<{}> takes either value or x/y/z, not both", e.tag),
            ));
        }
        let n = parse_n(&v.value, 3, &v.loc)?;
        return Ok(DVec3::new(n[0], n[1], n[2]));
    }
    let mut out = [default; 3];
    for (i, name) in ["x", "y", "z"].iter().enumerate() {
        if let Some(a) = e.attr(name) {
            out[i] = parse_f64(&a.value, &a.loc)?;
        }
    }
    Ok(DVec3::from_array(out))
}
