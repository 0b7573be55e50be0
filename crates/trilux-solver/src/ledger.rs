//! The energy ledger (docs/solver.md, "Energy ledger"): where every watt
//! of emitted flux went.
//!
//! Kept in f64 per band. For each shot of a source with unshot flux δΦ_S:
//! δΦ_S leaves the residual; the flux arriving on receivers through the links
//! splits there into absorbed and reflected; the reflected part becomes new
//! unshot flux (residual); what did not arrive anywhere escaped. Hence
//! `emitted = absorbed + escaped + residual` by construction; the meaningful
//! checks are that no term is negative and that escaped flux is small in a
//! closed scene (it then measures the form-factor error).

use serde::{Deserialize, Serialize};
use trilux_color::Spectrum;

/// Per-band flux totals in watts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ledger {
    /// Total flux emitted by all emitters (IF of paper §6).
    pub emitted: Vec<f64>,
    /// Flux absorbed at receiving elements.
    pub absorbed: Vec<f64>,
    /// Flux that left the scene or was lost to form-factor error.
    pub escaped: Vec<f64>,
    /// The smallest escaped flux of any single shot (band minimum): must not
    /// be negative.
    pub min_shot_escaped: f64,
    /// The smallest flux absorbed at any single receiving element group of
    /// any shot (band minimum): must not be negative.
    pub min_element_absorbed: f64,
}

impl Ledger {
    /// Books one shot of flux `phi`: what did not arrive anywhere escaped,
    /// `absorbed` of what arrived was absorbed; keeps the smallest share
    /// that escaped (negative would mean the shot created energy).
    pub(crate) fn book_shot<const N: usize>(
        &mut self,
        phi: Spectrum<N>,
        arrived: Spectrum<N>,
        absorbed: Spectrum<N>,
    ) {
        let escaped = phi - arrived;
        for b in 0..N {
            self.escaped[b] += escaped[b];
            self.absorbed[b] += absorbed[b];
        }
        let rel = escaped.min_value() / phi.max_value().max(1e-300);
        self.min_shot_escaped = self.min_shot_escaped.min(rel);
    }

    /// An empty ledger for `bands` bands with the given emitted flux.
    pub fn new(emitted: Vec<f64>) -> Self {
        let n = emitted.len();
        Ledger {
            emitted,
            absorbed: vec![0.0; n],
            escaped: vec![0.0; n],
            // Fractions are at most 1: start there so that the minima
            // report what the shots did, not a clamp at zero.
            min_shot_escaped: 1.0,
            min_element_absorbed: 1.0,
        }
    }
}
