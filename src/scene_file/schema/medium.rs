//! Participating media inside (or outside) an entity's shape.

use super::Color;
use serde::Deserialize;

/// A homogeneous participating medium filling a closed shape: absorption and scattering
/// coefficients per scene unit, and the Henyey–Greenstein asymmetry g.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, try_from = "MediumRaw")]
pub struct MediumSpec {
    /// Absorption coefficient per scene unit, every channel finite and >= 0.
    pub sigma_a: Color,
    /// Scattering coefficient per scene unit, every channel finite and >= 0.
    pub sigma_s: Color,
    /// Henyey–Greenstein asymmetry in (-1, 1): > 0 scatters forward, 0 (default) evenly.
    pub g: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MediumRaw {
    sigma_a: Color,
    sigma_s: Color,
    #[serde(default)]
    g: f32,
}

impl TryFrom<MediumRaw> for MediumSpec {
    type Error = String;
    fn try_from(m: MediumRaw) -> Result<Self, String> {
        for (name, c) in [("sigma_a", m.sigma_a), ("sigma_s", m.sigma_s)] {
            let v = c.vec();
            if !(v.is_finite() && v.min_element() >= 0.0) {
                return Err(format!(
                    "field `{name}`: must be finite and >= 0 in every channel, got Rgb({}, {}, {})",
                    v.x, v.y, v.z
                ));
            }
        }
        if !(m.g.is_finite() && m.g > -1.0 && m.g < 1.0) {
            return Err(format!("field `g`: must be in (-1, 1), got {}", m.g));
        }
        Ok(MediumSpec {
            sigma_a: m.sigma_a,
            sigma_s: m.sigma_s,
            g: m.g,
        })
    }
}
