//! RefineAndLink (paper §3.2.2, Fig. 4–5, §4.3; docs/solver.md).
//!
//! A shot refines in two stages, both creating links that live only for
//! this shot (paper §4.2):
//!
//! 1. **Pair links** i → j between the source's elements and the elements
//!    of every receiving side (the two-point part, as in hierarchical
//!    radiosity): refined until the form-factor estimates are below FFErr and
//!    visibility is not partial, or until the flux the link carries is below
//!    the photometric threshold. The flux arriving through a pair link is
//!    π T_ij δL_i; its Lambertian share goes straight into j's radiance.
//! 2. **Three-point links** (i j) → (j k), from each pair link into every
//!    stored interaction hierarchy leaving j's side (its glossy part):
//!    refined by the BRDF error FrErr, the form factor and visibility of
//!    (j, k), and the photometric criterion on the flux that would go on
//!    towards k. The three subdivision cases apply: split I
//!    (sender sub-pairs i_m j), split K (receiver nodes j k_m), or split J
//!    (matched pairs i j_m → j_m k only; docs/solver.md, "RefineAndLink").
//!
//! Senders are never stored in the sender's hierarchy by refinement: a
//! finer sender pair than the stored nodes is *virtual*, with the unshot
//! radiance of the deepest stored node containing it (piecewise constant, so
//! this is exact). Only receiving hierarchies grow, and they are disjoint
//! across the parallel tasks of one shot.
//!
//! Files, in reading order: `context` (what refinement reads, T through
//! the cache), `pair` (stage 1), `triple` (stage 2, its tests in `triple_tests`), `incidences` (stage 2's sub-pairs, once per
//! shot), `narrow_lobe` (the
//! sampled lobes stage 2 uses). The links and senders are in
//! `crate::link`.

mod context;
mod incidences;
#[cfg(test)]
mod late_tests;
mod narrow_lobe;
mod pair;
mod triple;
#[cfg(test)]
mod triple_tests;

pub(crate) use context::{Lateness, RefineContext, disc_facing};
pub(crate) use incidences::IncidenceMemo;
pub(crate) use triple::{Incidence, TripleTask};
