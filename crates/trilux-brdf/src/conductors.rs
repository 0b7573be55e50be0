//! Mitsuba 3's named conductors (`material="Cu"` on `conductor` and
//! `roughconductor`): the complex index of refraction η + i k of each, as
//! measured spectra.
//!
//! The tables in `src/ior/` are Mitsuba 3.9.1's `data/ior/*.spd`, byte
//! for byte (their README says where the measurements come from: the
//! luxpop.com compilation of Palik's *Handbook of Optical Constants of
//! Solids* and the CXRO/LLNL tables). Each file holds one wavelength (nm)
//! and one value a line; `#` starts a comment line. Mitsuba reads them
//! with `spectrum_from_file` and, in its RGB variants, converts them with
//! `spectrum_list_to_srgb(λ, v, bounded = false, d65 = false)`
//! (`include/mitsuba/render/ior.h`, `ior_from_file`), which is
//! [`ColorParam::Measured`]'s conversion.

use trilux_color::ColorParam;

/// One named conductor: its name and its η and k tables as written.
struct Named {
    name: &'static str,
    eta: &'static str,
    k: &'static str,
}

macro_rules! named {
    ($name:literal) => {
        Named {
            name: $name,
            eta: include_str!(concat!("ior/", $name, ".eta.spd")),
            k: include_str!(concat!("ior/", $name, ".k.spd")),
        }
    };
}

/// Every conductor Mitsuba 3.9.1 names (its `data/ior` folder), in
/// case-insensitive alphabetical order.
const NAMED: [Named; 71] = [
    named!("a-C"),
    named!("Ag"),
    named!("Al"),
    named!("AlAs"),
    named!("AlAs_palik"),
    named!("AlSb"),
    named!("AlSb_palik"),
    named!("Au"),
    named!("Be"),
    named!("Be_palik"),
    named!("Cr"),
    named!("CsI"),
    named!("CsI_palik"),
    named!("Cu"),
    named!("Cu2O"),
    named!("Cu2O_palik"),
    named!("Cu_palik"),
    named!("CuO"),
    named!("CuO_palik"),
    named!("d-C"),
    named!("d-C_palik"),
    named!("Hg"),
    named!("Hg_palik"),
    named!("HgTe"),
    named!("HgTe_palik"),
    named!("Ir"),
    named!("Ir_palik"),
    named!("K"),
    named!("K_palik"),
    named!("Li"),
    named!("Li_palik"),
    named!("MgO"),
    named!("MgO_palik"),
    named!("Mo"),
    named!("Mo_palik"),
    named!("Na_palik"),
    named!("Nb"),
    named!("Nb_palik"),
    named!("Ni_palik"),
    named!("Rh"),
    named!("Rh_palik"),
    named!("Se"),
    named!("Se-e"),
    named!("Se-e_palik"),
    named!("Se_palik"),
    named!("SiC"),
    named!("SiC_palik"),
    named!("SnTe"),
    named!("SnTe_palik"),
    named!("Ta"),
    named!("Ta_palik"),
    named!("Te"),
    named!("Te-e"),
    named!("Te-e_palik"),
    named!("Te_palik"),
    named!("ThF4"),
    named!("ThF4_palik"),
    named!("TiC"),
    named!("TiC_palik"),
    named!("TiN"),
    named!("TiN_palik"),
    named!("TiO2"),
    named!("TiO2-e"),
    named!("TiO2-e_palik"),
    named!("TiO2_palik"),
    named!("V_palik"),
    named!("VC"),
    named!("VC_palik"),
    named!("VN"),
    named!("VN_palik"),
    named!("W"),
];

/// The names `material` accepts, as Mitsuba spells them (case matters,
/// as for Mitsuba's file names); `none` (Fresnel = 1) is the caller's.
pub fn conductor_names() -> impl Iterator<Item = &'static str> {
    NAMED.iter().map(|n| n.name)
}

/// The measured (η, k) of the conductor Mitsuba names `name`, or `None`
/// for a name it does not have.
pub fn named_conductor(name: &str) -> Option<(ColorParam, ColorParam)> {
    let n = NAMED.iter().find(|n| n.name == name)?;
    Some((
        ColorParam::Measured(parse_spd(n.eta)),
        ColorParam::Measured(parse_spd(n.k)),
    ))
}

/// Mitsuba's `spectrum_from_file`: blank lines and lines starting with
/// `#` skipped, two numbers a line (wavelength in nm, value). The tables
/// are fixed data checked by this module's tests, so a malformed line
/// cannot occur; it would be skipped.
fn parse_spd(text: &str) -> Vec<(f64, f64)> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .filter_map(|l| {
            let mut it = l.split_whitespace().map(str::parse::<f64>);
            match (it.next(), it.next()) {
                (Some(Ok(w)), Some(Ok(v))) => Some((w, v)),
                _ => None,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_table_is_whole_and_reaches_the_visible_range() {
        for n in &NAMED {
            for text in [n.eta, n.k] {
                let rows = text
                    .lines()
                    .filter(|l| !l.trim().is_empty() && !l.trim().starts_with('#'))
                    .count();
                let s = parse_spd(text);
                assert_eq!(s.len(), rows, "{}: a line did not parse", n.name);
                assert!(s.windows(2).all(|w| w[0].0 < w[1].0), "{}", n.name);
                assert!(s.iter().all(|&(w, v)| w.is_finite() && v.is_finite()));
                // Some stop short of 360–830 nm (AlSb: 302–590 nm, d-C:
                // 347–656 nm); beyond its ends a table is 0, as Mitsuba's
                // RGB conversion takes it.
                assert!(s[0].0 < 400.0 && s[s.len() - 1].0 > 580.0, "{}", n.name);
            }
        }
    }

    #[test]
    fn copper_in_rgb_is_mitsubas() {
        // Mitsuba 3.9.1, scalar_rgb: `mi.traverse` of
        // <bsdf type="conductor"><string name="material" value="Cu"/>.
        let (eta, k) = named_conductor("Cu").unwrap_or_else(|| panic!("Cu"));
        let eta = eta.unbounded::<3>().unwrap_or_else(|e| panic!("{e}"));
        let k = k.unbounded::<3>().unwrap_or_else(|e| panic!("{e}"));
        let (want_eta, want_k) = ([0.201005, 0.92375, 1.10222], [3.91326, 2.45305, 2.14209]);
        for c in 0..3 {
            assert!(
                (eta.0[c] - want_eta[c]).abs() < 2e-5 * want_eta[c],
                "{eta:?}"
            );
            assert!((k.0[c] - want_k[c]).abs() < 2e-5 * want_k[c], "{k:?}");
        }
        assert!(named_conductor("cu").is_none() && named_conductor("none").is_none());
        assert_eq!(conductor_names().count(), 71);
    }
}
