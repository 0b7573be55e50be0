//! Indices of refraction as Mitsuba 3 writes them: a `<float>`, or one of
//! its named indices (`ior.h`, trilux-brdf's `NAMED_IORS`), shared by the
//! plastics (`crate::material`) and the panes of glass (`crate::glass`).

use trilux_brdf::{NAMED_IORS, named_ior};

use crate::error::{Result, SceneError};
use crate::props::Props;

/// An index of refraction given as a `<float>` or by one of Mitsuba's
/// names (`default` when absent); finite and positive.
pub(crate) fn ior(props: &Props<'_>, name: &str, default: &str) -> Result<f64> {
    let loc = props.loc(name);
    let value = match props.float(name) {
        Ok(Some(v)) => v,
        Ok(None) => named_ior(default).unwrap_or(1.0),
        Err(_) => {
            let given = props.string(name)?.unwrap_or_default();
            named_ior(&given).ok_or_else(|| {
                let names: Vec<&str> = NAMED_IORS.iter().map(|(n, _)| *n).collect();
                SceneError::at(
                    &loc,
                    format!(
                        "unknown index of refraction \"{given}\" for {name} (a float or one of: {})",
                        names.join(", ")
                    ),
                )
            })?
        }
    };
    if !(value > 0.0 && value.is_finite()) {
        return Err(SceneError::at(
            &loc,
            format!("{name} must be positive and finite, found {value}"),
        ));
    }
    Ok(value)
}
