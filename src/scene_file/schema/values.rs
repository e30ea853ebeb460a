//! Checked values shared by the schema: finite vectors, range-checked numbers and scales.

use serde::Deserialize;
use serde::de::{self, Deserializer, IgnoredAny, SeqAccess, Visitor};
use std::fmt;

/// A finite 3-vector written `(x, y, z)`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(try_from = "(f32, f32, f32)")]
pub struct V3(pub [f32; 3]);

impl V3 {
    /// The vector as glam's type.
    pub fn vec(&self) -> glam::Vec3 {
        glam::Vec3::from_array(self.0)
    }
}

impl TryFrom<(f32, f32, f32)> for V3 {
    type Error = String;
    fn try_from((x, y, z): (f32, f32, f32)) -> Result<Self, String> {
        if x.is_finite() && y.is_finite() && z.is_finite() {
            Ok(V3([x, y, z]))
        } else {
            Err(format!("coordinates must be finite, got ({x}, {y}, {z})"))
        }
    }
}

macro_rules! checked_number {
    ($(#[$doc:meta])* $name:ident($t:ty, $tstr:literal), $ok:expr, $what:literal) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
        #[serde(try_from = $tstr)]
        pub struct $name(pub $t);

        impl TryFrom<$t> for $name {
            type Error = String;
            fn try_from(x: $t) -> Result<Self, String> {
                #[allow(clippy::redundant_closure_call)]
                if ($ok)(x) {
                    Ok($name(x))
                } else {
                    Err(format!(concat!("must be ", $what, ", got {}"), x))
                }
            }
        }
    };
}

checked_number!(
    /// The sun's elevation above the horizon in degrees.
    SunElevation(f32, "f32"), |x: f32| (0.0..=90.0).contains(&x), "in [0, 90] degrees");
checked_number!(
    /// Atmospheric turbidity of the sky model.
    Turbidity(f32, "f32"), |x: f32| (1.0..=10.0).contains(&x), "in [1, 10]");
checked_number!(
    /// The relMSE a render may stop at: in (0, 1].
    TargetError(f64, "f64"), |x: f64| x > 0.0 && x <= 1.0,
    "a relative MSE in (0, 1], e.g. 0.01");
checked_number!(
    /// A finite number (an angle in degrees, say).
    Finite(f32, "f32"), |x: f32| x.is_finite(), "a finite number");
checked_number!(
    /// A finite number > 0.
    Positive(f32, "f32"), |x: f32| x.is_finite() && x > 0.0, "a finite number > 0");
checked_number!(
    /// A number in [0, 1].
    Unit(f32, "f32"), |x: f32| (0.0..=1.0).contains(&x), "in [0, 1]");
checked_number!(
    /// A finite number >= 0.
    NonNegative(f32, "f32"), |x: f32| x.is_finite() && x >= 0.0, "a finite number >= 0");
checked_number!(
    /// Vertical field of view in degrees.
    FovY(f32, "f32"), |x: f32| x.is_finite() && x > 0.0 && x < 180.0, "in (0, 180) degrees");
checked_number!(
    /// Image width or height in pixels.
    ImageDim(u32, "u32"), |x: u32| (1..=65536).contains(&x), "in 1..=65536 pixels");
checked_number!(
    /// Scattering events after which a path ends: at most 1024, so that a path in a closed
    /// mirror (whose throughput Russian roulette never lowers) still ends.
    MaxDepth(u32, "u32"), |x: u32| x <= 1024, "at most 1024 scattering events");
checked_number!(
    /// Samples per pixel.
    Spp(u32, "u32"), |x: u32| x >= 1, "at least 1 sample per pixel");
checked_number!(
    /// Number of aperture blades: 0 for a round aperture, otherwise at least 3.
    #[derive(Default)]
    Blades(u32, "u32"), |x: u32| x == 0 || (3..=64).contains(&x), "0 (round) or 3..=64");
checked_number!(
    /// Wavelengths carried per path in spectral mode: 4 (hero wavelength sampling) or 1. Two
    /// or three would silently carry four, so they are refused.
    Wavelengths(u32, "u32"), |x: u32| x == 1 || x == 4, "1 or 4 wavelengths per path");

/// `scale: 2.0` or `scale: (1.0, 2.0, 1.0)`; every component non-zero and finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale(pub [f32; 3]);

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Scale;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or a triple (x, y, z)")
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<Scale, E> {
                check_scale([x as f32; 3])
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<Scale, E> {
                check_scale([x as f32; 3])
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<Scale, E> {
                check_scale([x as f32; 3])
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Scale, A::Error> {
                let mut s = [0.0f32; 3];
                for (i, c) in s.iter_mut().enumerate() {
                    *c = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<IgnoredAny>()?.is_some() {
                    return Err(de::Error::invalid_length(4, &self));
                }
                check_scale(s)
            }
        }
        d.deserialize_any(V)
    }
}

fn check_scale<E: de::Error>(s: [f32; 3]) -> Result<Scale, E> {
    if s.iter().all(|c| c.is_finite() && *c != 0.0) {
        Ok(Scale(s))
    } else {
        Err(E::custom(format!(
            "scale must be finite and non-zero on every axis, got ({}, {}, {})",
            s[0], s[1], s[2]
        )))
    }
}
