//! Named metals: the measured complex refractive index n + ik that spectral transport
//! evaluates at each wavelength, and the colour RGB transport uses instead.

use super::metals_data::{METAL_FIRST_NM, METAL_NK, METAL_ROWS, METAL_STEP_NM};
use glam::Vec3;

/// A metal with a measured complex IOR (tables and their sources: `scripts/metal_tables.py`),
/// named in scene files by its chemical symbol.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize)]
pub enum Metal {
    /// Gold.
    Au,
    /// Silver.
    Ag,
    /// Copper.
    Cu,
    /// Aluminium.
    Al,
    /// Chromium.
    Cr,
    /// Titanium.
    Ti,
    /// Nickel.
    Ni,
    /// Platinum.
    Pt,
}

impl Metal {
    /// Every metal, in the order of the tables.
    pub const ALL: [Metal; 8] = [
        Metal::Au,
        Metal::Ag,
        Metal::Cu,
        Metal::Al,
        Metal::Cr,
        Metal::Ti,
        Metal::Ni,
        Metal::Pt,
    ];

    /// The chemical symbol, as the scene format writes it.
    pub fn name(self) -> &'static str {
        match self {
            Metal::Au => "Au",
            Metal::Ag => "Ag",
            Metal::Cu => "Cu",
            Metal::Al => "Al",
            Metal::Cr => "Cr",
            Metal::Ti => "Ti",
            Metal::Ni => "Ni",
            Metal::Pt => "Pt",
        }
    }

    /// (n, k) at `lambda` nm: linear between the 5 nm rows, the end rows beyond them.
    #[inline(always)]
    pub fn nk(self, lambda: f32) -> (f32, f32) {
        let table = &METAL_NK[self as usize];
        let x = (lambda - METAL_FIRST_NM) / METAL_STEP_NM;
        // NaN fails the comparison and reads row 0.
        let x = if x >= 0.0 {
            x.min((METAL_ROWS - 1) as f32)
        } else {
            0.0
        };
        // Through i32: x is in range, and a float → usize cast costs a dozen instructions.
        let i = (x as i32 as usize).min(METAL_ROWS - 2);
        let f = x - i as f32;
        let (a, b) = (table[i], table[i + 1]);
        (a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f)
    }

    /// Normal-incidence reflectance ((n − 1)² + k²) / ((n + 1)² + k²) at `lambda` nm.
    pub fn reflectance_at(self, lambda: f32) -> f32 {
        let (n, k) = self.nk(lambda);
        ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k)
    }

    /// The colour of the normal-incidence reflectance under D65, linear sRGB clamped to
    /// [0, 1]: what RGB transport uses as Schlick's r0 for this metal.
    pub fn reflectance_rgb(self) -> Vec3 {
        let xyz = super::reflectance_to_xyz(|l| self.reflectance_at(l));
        super::xyz_to_linear_srgb(xyz).clamp(Vec3::ZERO, Vec3::ONE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables hold what the literature reports in the visible (n, k at 550 nm within a
    /// few per cent of the sources' own rows), and the colours are the metals' familiar ones.
    #[test]
    fn metals_have_their_measured_constants_and_colours() {
        // Johnson & Christy 1972 near 550 nm (2.25 eV, 551 nm): Au 0.43 + 2.46i,
        // Ag 0.059 + 3.59i (2.26 eV), Cu 1.03 + 2.58i (2.24 eV: 0.94–1.12).
        let near = |m: Metal, n: f32, k: f32, tol: f32| {
            let (a, b) = m.nk(551.0);
            assert!(
                (a - n).abs() <= tol * n.max(0.2) && (b - k).abs() <= tol * k,
                "{m:?}: ({a}, {b}) vs ({n}, {k})"
            );
        };
        near(Metal::Au, 0.43, 2.46, 0.15);
        near(Metal::Ag, 0.059, 3.59, 0.15);
        near(Metal::Cu, 1.03, 2.58, 0.15);
        let au = Metal::Au.reflectance_rgb();
        let cu = Metal::Cu.reflectance_rgb();
        let ag = Metal::Ag.reflectance_rgb();
        let al = Metal::Al.reflectance_rgb();
        // Gold and copper are warm (red > green > blue); silver and aluminium nearly grey
        // and bright.
        assert!(au.x > au.y && au.y > au.z, "{au}");
        assert!(
            cu.x > cu.y && cu.y > cu.z && cu.x - cu.z > au.x - au.z - 0.3,
            "{cu}"
        );
        for c in [ag, al] {
            assert!(
                c.min_element() > 0.85 && c.max_element() - c.min_element() < 0.1,
                "{c}"
            );
        }
        for m in Metal::ALL {
            let c = m.reflectance_rgb();
            assert!(
                c.min_element() > 0.3 && c.max_element() <= 1.0,
                "{m:?}: {c}"
            );
            for l in [360.0, 555.5, 830.0, 1000.0, f32::NAN] {
                let (n, k) = m.nk(l);
                assert!(
                    n.is_finite() && k.is_finite() && n > 0.0 && k > 0.0,
                    "{m:?} {l}"
                );
            }
        }
    }
}
