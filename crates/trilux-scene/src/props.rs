//! The parameters of one plugin element, with Mitsuba's bookkeeping: every
//! parameter must be queried by the plugin that receives it, and whatever is
//! left over is an "unknown parameter" error (Mitsuba 3 does the same check).
//! Queries check types: asking for a float where a string was written is an
//! error naming both.

use std::cell::Cell;

use glam::DVec3;
use trilux_color::ColorParam;

use crate::error::{Result, SceneError, SourceLocation};
use crate::transform::TransformValue;
use crate::value::{VALUE_TAGS, Value, parse_value};
use crate::xml::Element;

struct Param {
    name: String,
    value: Value,
    loc: SourceLocation,
    used: Cell<bool>,
}

/// Parameters and nested objects of one plugin element.
pub(crate) struct Props<'a> {
    owner: &'a Element,
    params: Vec<Param>,
    /// Nested plugin elements (`bsdf`, `emitter`, `film`, ...), in order.
    pub objects: Vec<&'a Element>,
}

impl<'a> Props<'a> {
    /// Splits the children of `owner` into values and nested objects.
    pub fn new(owner: &'a Element) -> Result<Self> {
        let mut params: Vec<Param> = Vec::new();
        let mut objects = Vec::new();
        for child in &owner.children {
            if VALUE_TAGS.contains(&child.tag.as_str()) {
                let (name, value) = parse_value(child)?;
                if params.iter().any(|p| p.name == name) {
                    return Err(SceneError::at(
                        &child.loc,
                        format!(
                            "parameter \"{name}\" is given twice in {}",
                            owner.describe()
                        ),
                    ));
                }
                params.push(Param {
                    name,
                    value,
                    loc: child.loc.clone(),
                    used: Cell::new(false),
                });
            } else {
                objects.push(child);
            }
        }
        Ok(Props {
            owner,
            params,
            objects,
        })
    }

    /// The element these parameters belong to.
    pub fn owner(&self) -> &'a Element {
        self.owner
    }

    fn find(&self, name: &str) -> Option<&Param> {
        let p = self.params.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// True when a parameter `name` was written (does not consume it).
    pub fn has(&self, name: &str) -> bool {
        self.params.iter().any(|p| p.name == name)
    }

    /// Where parameter `name` was written, or the owner element.
    pub fn loc(&self, name: &str) -> SourceLocation {
        self.params
            .iter()
            .find(|p| p.name == name)
            .map_or_else(|| self.owner.loc.clone(), |p| p.loc.clone())
    }

    fn wrong_type(&self, p: &Param, expected: &str) -> SceneError {
        SceneError::at(
            &p.loc,
            format!(
                "parameter \"{}\" of {} must be a <{expected}>, found <{}>",
                p.name,
                self.owner.describe(),
                p.value.kind()
            ),
        )
    }

    /// A `<float>` (an `<integer>` is accepted too).
    pub fn float(&self, name: &str) -> Result<Option<f64>> {
        match self.find(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Float(v) => Ok(Some(v)),
                Value::Integer(v) => Ok(Some(v as f64)),
                _ => Err(self.wrong_type(p, "float")),
            },
        }
    }

    /// An `<integer>`.
    pub fn integer(&self, name: &str) -> Result<Option<i64>> {
        match self.find(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Integer(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "integer")),
            },
        }
    }

    /// A `<boolean>`.
    pub fn boolean(&self, name: &str) -> Result<Option<bool>> {
        match self.find(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Boolean(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "boolean")),
            },
        }
    }

    /// A `<string>`.
    pub fn string(&self, name: &str) -> Result<Option<String>> {
        match self.find(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::String(v) => Ok(Some(v.clone())),
                _ => Err(self.wrong_type(p, "string")),
            },
        }
    }

    /// A `<point>` or `<vector>`.
    pub fn vec3(&self, name: &str) -> Result<Option<DVec3>> {
        match self.find(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Vec3(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "point")),
            },
        }
    }

    /// A colour: `<float>`, `<rgb>` or `<spectrum>`.
    pub fn color(&self, name: &str) -> Result<Option<ColorParam>> {
        match self.find(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Float(v) => Ok(Some(ColorParam::Float(*v))),
                Value::Integer(v) => Ok(Some(ColorParam::Float(*v as f64))),
                Value::Color(c) => Ok(Some(c.clone())),
                _ => Err(self.wrong_type(p, "rgb, spectrum or float")),
            },
        }
    }

    /// A `<transform>`.
    pub fn transform(&self, name: &str) -> Result<Option<TransformValue>> {
        match self.find(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Transform(t) => Ok(Some(t.clone())),
                _ => Err(self.wrong_type(p, "transform")),
            },
        }
    }

    /// Marks parameters that do not change radiance as read (they are
    /// accepted and ignored).
    pub fn ignore(&self, names: &[&str]) {
        for n in names {
            self.find(n);
        }
    }

    /// Fails on the first parameter nobody asked for.
    pub fn finish(&self) -> Result<()> {
        match self.params.iter().find(|p| !p.used.get()) {
            None => Ok(()),
            Some(p) => Err(SceneError::at(
                &p.loc,
                format!(
                    "unknown parameter \"{}\" for {}",
                    p.name,
                    self.owner.describe()
                ),
            )),
        }
    }

    /// Fails on any nested object (for plugins that take none).
    pub fn no_objects(&self) -> Result<()> {
        match self.objects.first() {
            None => Ok(()),
            Some(o) => Err(SceneError::at(
                &o.loc,
                format!("{} cannot contain {}", self.owner.describe(), o.describe()),
            )),
        }
    }
}
