//! The film's reconstruction filters: the scene model's type, whose
//! weights are Mitsuba 3's (`trilux_scene::rfilter`, with its tests
//! against Mitsuba's own values).

pub use trilux_scene::rfilter::ReconstructionFilter;
