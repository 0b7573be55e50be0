//! The film's reconstruction filters: the sensor's plain data, whose
//! weights are Mitsuba 3's (`trilux_geometry::sensor::rfilter`, with its
//! tests against Mitsuba's own values), shared with the scene loader.

pub use trilux_geometry::sensor::ReconstructionFilter;
