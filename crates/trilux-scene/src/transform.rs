//! `<transform>`: translate, scale, rotate, matrix and lookat, composed in
//! the order written (the first listed acts first: each new operation
//! multiplies from the left, `world_from_object = op_n · … · op_1`), exactly
//! as Mitsuba 3 composes them.

use glam::{DMat3, DMat4, DVec3, DVec4};
use serde::Serialize;

use trilux_geometry::limits::{beyond, within};

use crate::error::{Result, SceneError, SourceLocation};
use crate::numbers::{parse_f64, parse_list, parse_n, parse_xyz};
use crate::xml::Element;

/// A camera placement as written in `<lookat origin target up>`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LookAt {
    /// Eye position.
    pub origin: DVec3,
    /// Point looked at.
    pub target: DVec3,
    /// Up direction as written (or Mitsuba's choice when omitted).
    pub up: DVec3,
}

/// A parsed `<transform>`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TransformValue {
    /// The composed matrix (maps object space to world space).
    pub matrix: DMat4,
    /// Set when the transform is exactly one `<lookat>`.
    pub lookat: Option<LookAt>,
}

/// Parses the operations of a `<transform>` element.
pub(crate) fn parse(e: &Element) -> Result<TransformValue> {
    let mut matrix = DMat4::IDENTITY;
    let mut lookats = Vec::new();
    for op in &e.children {
        let m = match op.tag.as_str() {
            "translate" => {
                op.check_attrs(&["value", "x", "y", "z"])?;
                DMat4::from_translation(parse_xyz(op, 0.0)?)
            }
            "scale" => {
                op.check_attrs(&["value", "x", "y", "z"])?;
                let s = match op.attr("value") {
                    Some(v) => {
                        if ["x", "y", "z"].iter().any(|n| op.attr(n).is_some()) {
                            return Err(SceneError::at(
                                &v.loc,
                                "<scale> takes either value or x/y/z, not both",
                            ));
                        }
                        match parse_list(&v.value, &v.loc)?.as_slice() {
                            [s] => DVec3::splat(*s),
                            [x, y, z] => DVec3::new(*x, *y, *z),
                            n => {
                                return Err(SceneError::at(
                                    &v.loc,
                                    format!("<scale> takes 1 or 3 numbers, found {}", n.len()),
                                ));
                            }
                        }
                    }
                    None => parse_xyz(op, 1.0)?,
                };
                DMat4::from_scale(s)
            }
            "rotate" => {
                op.check_attrs(&["value", "x", "y", "z", "angle"])?;
                let axis = parse_xyz(op, 0.0)?;
                let angle = op.required("angle")?;
                let degrees = parse_f64(&angle.value, &angle.loc)?;
                // Mitsuba uses the axis as written, without normalising it:
                // refuse what it would turn into a scale instead.
                if (axis.length() - 1.0).abs() > 1e-3 {
                    return Err(SceneError::at(
                        &op.loc,
                        format!(
                            "the <rotate> axis must be a unit vector, found length {} (Mitsuba does not normalise it)",
                            axis.length()
                        ),
                    ));
                }
                rotation(axis, degrees)
            }
            "matrix" => {
                op.check_attrs(&["value"])?;
                let v = op.required("value")?;
                let n = parse_n(&v.value, 16, &v.loc)?;
                // Written row by row; glam stores columns.
                DMat4::from_cols_array(&[
                    n[0], n[4], n[8], n[12], n[1], n[5], n[9], n[13], n[2], n[6], n[10], n[14],
                    n[3], n[7], n[11], n[15],
                ])
            }
            "lookat" => {
                op.check_attrs(&["origin", "target", "up"])?;
                let l = parse_lookat(op)?;
                lookats.push(l);
                world_from_camera(&l, &op.loc)?
            }
            other => {
                return Err(SceneError::at(
                    &op.loc,
                    format!(
                        "unknown transform operation <{other}> (supported: translate, scale, rotate, matrix, lookat)"
                    ),
                ));
            }
        };
        if !op.children.is_empty() {
            return Err(SceneError::at(
                &op.loc,
                format!("<{}> has no child elements", op.tag),
            ));
        }
        matrix = m * matrix;
    }
    let lookat = match (e.children.len(), lookats.as_slice()) {
        (1, [l]) => Some(*l),
        _ => None,
    };
    Ok(TransformValue { matrix, lookat })
}

/// Rotation by `degrees` about `axis` (right-handed), with Dr.Jit's formula
/// (used by Mitsuba) so that nearly-unit axes give bit-compatible matrices.
fn rotation(axis: DVec3, degrees: f64) -> DMat4 {
    let (s, c) = degrees.to_radians().sin_cos();
    let cm = 1.0 - c;
    let DVec3 { x, y, z } = axis;
    // Rows of the matrix, transposed into glam's columns.
    DMat4::from_cols(
        DVec4::new(c + x * x * cm, x * y * cm + z * s, x * z * cm - y * s, 0.0),
        DVec4::new(x * y * cm - z * s, c + y * y * cm, y * z * cm + x * s, 0.0),
        DVec4::new(x * z * cm + y * s, y * z * cm - x * s, c + z * z * cm, 0.0),
        DVec4::W,
    )
}

fn vec3_attr(op: &Element, name: &str) -> Result<Option<DVec3>> {
    op.attr(name)
        .map(|a| {
            let n = parse_n(&a.value, 3, &a.loc)?;
            Ok(DVec3::new(n[0], n[1], n[2]))
        })
        .transpose()
}

fn parse_lookat(op: &Element) -> Result<LookAt> {
    let missing = |n: &str| SceneError::at(&op.loc, format!("<lookat> needs \"{n}\""));
    let origin = vec3_attr(op, "origin")?.ok_or_else(|| missing("origin"))?;
    let target = vec3_attr(op, "target")?.ok_or_else(|| missing("target"))?;
    for (name, v) in [("origin", origin), ("target", target)] {
        let largest = v.abs().max_element();
        if !within(largest) {
            return Err(SceneError::at(
                &op.required(name)?.loc,
                format!("<lookat> {name}: {}", beyond(largest)),
            ));
        }
    }
    let dir = target - origin;
    if dir.length_squared() == 0.0 {
        return Err(SceneError::at(
            &op.loc,
            "<lookat> origin and target are the same point",
        ));
    }
    let up = match vec3_attr(op, "up")? {
        Some(up) => up,
        // Mitsuba picks the first vector of its orthonormal basis around dir.
        None => trilux_geometry::coordinate_system(dir.normalize()).0,
    };
    Ok(LookAt { origin, target, up })
}

/// Mitsuba's `look_at` matrix ([`trilux_geometry::look_at`], the one the
/// command line's `--lookat` uses too), refused at `loc` when up is
/// parallel to the viewing direction.
pub(crate) fn world_from_camera(l: &LookAt, loc: &SourceLocation) -> Result<DMat4> {
    trilux_geometry::look_at(l.origin, l.target, l.up).map_err(|_| {
        SceneError::at(
            loc,
            "<lookat> up is parallel to the viewing direction (or zero)",
        )
    })
}

/// The linear 3×3 part of an affine transform.
pub(crate) fn linear_part(m: &DMat4) -> DMat3 {
    DMat3::from_mat4(*m)
}
