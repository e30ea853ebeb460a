//! `Medium`: a homogeneous participating medium filling a closed shape.
//!
//! ```
//! # use prism::scene_file::schema::MediumSpec;
//! let m: MediumSpec = ron::from_str("(sigma_a: Rgb(0.005, 0.005, 0.005), sigma_s: Rgb(0.04, 0.04, 0.04), g: 0.2)").unwrap();
//! # let _ = m;
//! ```
//! On a Sphere or Box with no material, the shape is a pure boundary (fog in a room is a Box
//! with a medium); on a Dielectric, the medium is the inside of the glass. σa and σs are per
//! scene unit; g is the Henyey–Greenstein mean cosine. The camera's medium is the innermost
//! medium shape that contains it.

pub use crate::medium::HomogeneousMedium as Medium;
