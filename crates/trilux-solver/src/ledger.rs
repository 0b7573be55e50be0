//! The energy ledger (notes §7): where every watt of emitted flux went.
//!
//! Kept in f64 per band. For each shot of a source with unshot flux δΦ_S:
//! δΦ_S leaves the residual; the flux arriving on receivers through the links
//! splits there into absorbed and reflected; the reflected part becomes new
//! unshot flux (residual); what did not arrive anywhere escaped. Hence
//! `emitted = absorbed + escaped + residual` by construction; the meaningful
//! checks are that no term is negative and that escaped flux is small in a
//! closed scene (it then measures the form-factor error).

use serde::{Deserialize, Serialize};

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
    /// An empty ledger for `bands` bands with the given emitted flux.
    pub fn new(emitted: Vec<f64>) -> Self {
        let n = emitted.len();
        Ledger {
            emitted,
            absorbed: vec![0.0; n],
            escaped: vec![0.0; n],
            min_shot_escaped: 0.0,
            min_element_absorbed: 0.0,
        }
    }

    /// Relative imbalance |emitted − absorbed − escaped − residual| / emitted,
    /// the largest over bands.
    pub fn imbalance(&self, residual: &[f64]) -> f64 {
        let mut worst: f64 = 0.0;
        for b in 0..self.emitted.len() {
            let e = self.emitted[b];
            if e > 0.0 {
                let d = e - self.absorbed[b] - self.escaped[b] - residual[b];
                worst = worst.max(d.abs() / e);
            }
        }
        worst
    }
}
