//! Reconstruction filters, exactly as Mitsuba 3's `hdrfilm` applies them.
//!
//! A sample at film position p (pixels) contributes to every pixel whose
//! centre c lies within the filter's radius on both axes, with the separable
//! weight w(c_x − p_x) · w(c_y − p_y); each pixel is then divided by the sum of
//! the weights it received.
//!
//! - Gaussian (Mitsuba's default): stddev σ = 0.5 px, radius r = 4σ = 2 px,
//!   w(d) = max(0, exp(−d²/(2σ²)) − exp(−r²/(2σ²))).
//! - Box: radius 0.5 px, w(d) = 1 for |d| ≤ 0.5.

/// A separable reconstruction filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ReconstructionFilter {
    /// Mitsuba's `gaussian` with standard deviation `stddev` (default 0.5)
    /// and radius 4·stddev.
    Gaussian {
        /// Standard deviation in pixels.
        stddev: f64,
    },
    /// Mitsuba's `box`: each sample lands in its own pixel.
    Box,
}

impl Default for ReconstructionFilter {
    /// Mitsuba's default: Gaussian with stddev 0.5 px.
    fn default() -> Self {
        Self::Gaussian { stddev: 0.5 }
    }
}

impl ReconstructionFilter {
    /// Parses Mitsuba's `rfilter` type name (`gaussian`, `box`).
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "gaussian" => Some(Self::default()),
            "box" => Some(Self::Box),
            _ => None,
        }
    }

    /// Radius in pixels beyond which the weight is zero.
    pub fn radius(&self) -> f64 {
        match self {
            Self::Gaussian { stddev } => 4.0 * stddev,
            Self::Box => 0.5,
        }
    }

    /// One-axis weight at offset `d` (pixels) from the sample.
    pub fn eval(&self, d: f64) -> f64 {
        match *self {
            Self::Gaussian { stddev } => {
                let alpha = -1.0 / (2.0 * stddev * stddev);
                let r = self.radius();
                ((alpha * d * d).exp() - (alpha * r * r).exp()).max(0.0)
            }
            Self::Box => {
                if d.abs() <= 0.5 {
                    1.0
                } else {
                    0.0
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_is_mitsubas_formula() {
        let f = ReconstructionFilter::default();
        assert_eq!(f.radius(), 2.0);
        // Independent evaluation of max(0, exp(-d²/0.5) - exp(-4/0.5)).
        for d in [0.0, 0.3, 0.5, 1.0, 1.7, 2.0, 2.5] {
            let expected = ((-d * d / 0.5f64).exp() - (-8.0f64).exp()).max(0.0);
            assert!((f.eval(d) - expected).abs() < 1e-15, "d = {d}");
        }
        assert_eq!(f.eval(2.0), 0.0);
        assert_eq!(f.eval(-3.0), 0.0);
    }

    #[test]
    fn box_covers_one_pixel() {
        let f = ReconstructionFilter::Box;
        assert_eq!(f.eval(0.49), 1.0);
        assert_eq!(f.eval(-0.49), 1.0);
        assert_eq!(f.eval(0.51), 0.0);
    }
}
