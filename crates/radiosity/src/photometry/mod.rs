//! Photometric data of luminaires: how a real light fitting spreads its light.
//!
//! * [`ies`]: IES LM-63 files (the 1986, 1991, 1995, 2002 and 2019 variants), type C
//!   photometry, as a candela table that [`IesPhotometry::candela`] interpolates in any
//!   direction and [`IesPhotometry::table_lumens`] integrates over the sphere.
//!
//! Units: luminous intensity in candela (cd = lm/sr), flux in lumens (lm), angles in
//! radians at the API (files state degrees).

pub mod ies;

pub use ies::{IesError, IesPhotometry, IesProblem, IesVersion, Tilt};
