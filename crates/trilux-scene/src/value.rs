//! Typed parameter values: `<float>`, `<integer>`, `<boolean>`, `<string>`,
//! `<point>`, `<vector>`, `<rgb>`, `<spectrum>` and `<transform>`.
//!
//! Numbers are read by the `numbers` module (finite, in lists separated
//! by commas and/or spaces, as Mitsuba reads them).

use glam::DVec3;
use trilux_color::ColorParam;

use crate::error::{Result, SceneError, SourceLocation};
use crate::numbers::{parse_f64, parse_list, parse_xyz};
use crate::transform::{self, TransformValue};
use crate::xml::Element;

/// A parameter value as written.
#[derive(Clone, Debug)]
pub(crate) enum Value {
    /// `<float>`.
    Float(f64),
    /// `<integer>`.
    Integer(i64),
    /// `<boolean>`.
    Boolean(bool),
    /// `<string>`.
    String(String),
    /// `<point>` or `<vector>` (Mitsuba 3 stores both as a 3-array).
    Vec3(DVec3),
    /// `<rgb>`, or `<spectrum>`.
    Color(ColorParam),
    /// `<transform>`.
    Transform(TransformValue),
}

impl Value {
    /// The XML tag that writes this kind of value, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Float(_) => "float",
            Value::Integer(_) => "integer",
            Value::Boolean(_) => "boolean",
            Value::String(_) => "string",
            Value::Vec3(_) => "point/vector",
            Value::Color(ColorParam::Rgb(_)) => "rgb",
            Value::Color(_) => "spectrum",
            Value::Transform(_) => "transform",
        }
    }
}

/// The tags that write a parameter value (as opposed to a nested object).
pub(crate) const VALUE_TAGS: &[&str] = &[
    "float",
    "integer",
    "boolean",
    "string",
    "point",
    "vector",
    "rgb",
    "spectrum",
    "transform",
];

/// Parses a value element (one of [`VALUE_TAGS`]) into its name and value.
pub(crate) fn parse_value(e: &Element) -> Result<(String, Value)> {
    let name = e.required("name")?.value.clone();
    let value = match e.tag.as_str() {
        "transform" => {
            e.check_attrs(&["name"])?;
            Value::Transform(transform::parse(e)?)
        }
        "spectrum" if e.attr("type").is_some() => {
            e.check_attrs(&["name", "type"])?;
            Value::Color(spectrum_plugin(e)?)
        }
        tag => {
            if let Some(c) = e.children.first() {
                return Err(SceneError::at(
                    &c.loc,
                    format!("<{tag}> has no child elements"),
                ));
            }
            match tag {
                "float" | "integer" | "boolean" | "string" | "rgb" => {
                    e.check_attrs(&["name", "value"])?;
                    let a = e.required("value")?;
                    scalar_value(tag, &a.value, &a.loc)?
                }
                "spectrum" => {
                    e.check_attrs(&["name", "value"])?;
                    let a = e.required("value")?;
                    Value::Color(parse_spectrum(&a.value, &a.loc)?)
                }
                "point" | "vector" => {
                    e.check_attrs(&["name", "value", "x", "y", "z"])?;
                    Value::Vec3(parse_xyz(e, 0.0)?)
                }
                _ => {
                    return Err(SceneError::at(
                        &e.loc,
                        format!("<{tag}> is not a parameter value"),
                    ));
                }
            }
        }
    };
    Ok((name, value))
}

fn scalar_value(tag: &str, text: &str, loc: &SourceLocation) -> Result<Value> {
    Ok(match tag {
        "float" => Value::Float(parse_f64(text, loc)?),
        "integer" => {
            let t = text.trim();
            Value::Integer(
                t.parse()
                    .map_err(|_| SceneError::at(loc, format!("\"{t}\" is not an integer")))?,
            )
        }
        "boolean" => match text.trim().to_ascii_lowercase().as_str() {
            "true" => Value::Boolean(true),
            "false" => Value::Boolean(false),
            other => {
                return Err(SceneError::at(
                    loc,
                    format!("\"{other}\" is not a boolean (true or false)"),
                ));
            }
        },
        "string" => Value::String(text.to_string()),
        _ => {
            // rgb: one value (grey) or three.
            let v = parse_list(text, loc)?;
            match v.as_slice() {
                [g] => Value::Color(ColorParam::Rgb([*g; 3])),
                [r, g, b] => Value::Color(ColorParam::Rgb([*r, *g, *b])),
                _ => {
                    return Err(SceneError::at(
                        loc,
                        format!("<rgb> takes 1 or 3 numbers, found {}", v.len()),
                    ));
                }
            }
        }
    })
}

/// Hottest and coolest blackbody (K): beyond them Planck's law over 360–830
/// nm overflows or vanishes in double precision.
const BLACKBODY_KELVIN: std::ops::RangeInclusive<f64> = 1.0..=1.0e6;

/// A `<spectrum type="...">` plugin: `blackbody` with its `temperature`
/// (K), Mitsuba 3's spectral radiance of a black body, Planck's law
/// B(λ, T) = 2hc² / λ⁵ / (e^{hc/(λkT)} − 1) in W m⁻² sr⁻¹ nm⁻¹ over
/// 360–830 nm and zero outside, as samples every 5 nm (Planck's curve is
/// smooth: linear interpolation between them is within 1e-3).
fn spectrum_plugin(e: &Element) -> Result<ColorParam> {
    let t = e.required("type")?;
    if t.value != "blackbody" {
        return Err(SceneError::at(
            &t.loc,
            format!(
                "unknown spectrum plugin \"{}\" (only \"blackbody\")",
                t.value
            ),
        ));
    }
    let mut temperature = None;
    for c in &e.children {
        match (c.tag.as_str(), c.attr("name").map(|a| a.value.as_str())) {
            ("float", Some("temperature")) if temperature.is_none() => {
                c.check_attrs(&["name", "value"])?;
                let v = c.required("value")?;
                temperature = Some((parse_f64(&v.value, &v.loc)?, v.loc.clone()));
            }
            _ => {
                return Err(SceneError::at(
                    &c.loc,
                    "a blackbody <spectrum> takes one <float name=\"temperature\">",
                ));
            }
        }
    }
    let Some((kelvin, loc)) = temperature else {
        return Err(SceneError::at(
            &e.loc,
            "a blackbody <spectrum> needs <float name=\"temperature\" value=\"K\">",
        ));
    };
    if !BLACKBODY_KELVIN.contains(&kelvin) {
        return Err(SceneError::at(
            &loc,
            format!(
                "temperature must be between {} and {} K, found {kelvin}",
                BLACKBODY_KELVIN.start(),
                BLACKBODY_KELVIN.end()
            ),
        ));
    }
    Ok(ColorParam::Sampled(
        (0..=94)
            .map(|i| {
                let nm = 360.0 + 5.0 * f64::from(i);
                (nm, planck(nm, kelvin))
            })
            .collect(),
    ))
}

/// Planck's spectral radiance at `nm` nanometres and `kelvin`, per nm.
fn planck(nm: f64, kelvin: f64) -> f64 {
    const H: f64 = 6.626_070_15e-34;
    const C: f64 = 2.997_924_58e8;
    const K: f64 = 1.380_649e-23;
    let l = nm * 1e-9;
    2.0 * H * C * C / l.powi(5) / (H * C / (l * K * kelvin)).exp_m1() * 1e-9
}

/// Parses a `<spectrum value>`: one number (a constant spectrum) or
/// `λ:v` pairs in nm, strictly ascending in wavelength.
pub(crate) fn parse_spectrum(text: &str, loc: &SourceLocation) -> Result<ColorParam> {
    if !text.contains(':') {
        let v = parse_list(text, loc)?;
        return match v.as_slice() {
            [c] => Ok(ColorParam::Constant(*c)),
            _ => Err(SceneError::at(
                loc,
                "<spectrum> takes one number or wavelength:value pairs (\"400:0.5, 500:0.6\")",
            )),
        };
    }
    let mut samples: Vec<(f64, f64)> = Vec::new();
    for pair in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (l, v) = pair.split_once(':').ok_or_else(|| {
            SceneError::at(loc, format!("\"{pair}\" is not a wavelength:value pair"))
        })?;
        let (l, v) = (parse_f64(l, loc)?, parse_f64(v, loc)?);
        if l <= 0.0 {
            return Err(SceneError::at(
                loc,
                format!("wavelength {l} nm is not positive"),
            ));
        }
        if let Some(&(prev, _)) = samples.last()
            && l <= prev
        {
            return Err(SceneError::at(
                loc,
                format!("wavelengths must increase ({l} nm follows {prev} nm)"),
            ));
        }
        samples.push((l, v));
    }
    if samples.len() < 2 {
        return Err(SceneError::at(
            loc,
            "a sampled <spectrum> needs at least two wavelength:value pairs",
        ));
    }
    Ok(ColorParam::Sampled(samples))
}
