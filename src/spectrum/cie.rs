//! CIE 1931 colour matching, the D65 illuminant and the sRGB matrices.

use glam::{Mat3, Vec2, Vec3};

use super::cie_data::{CIE_1931_2DEG, CIE_D65, CMF_FIRST_NM, D65_FIRST_NM, D65_STEP_NM};
use super::{N_LAMBDA, SampledSpectrum, Wavelengths};

/// Number of 1 nm rows of the colour matching table (360..=830).
pub(super) const CMF_ROWS: usize = CIE_1931_2DEG.len();

/// Σ ȳ over the 1 nm table, f64.
const Y_SUM: f64 = {
    let mut s = 0.0;
    let mut i = 0;
    while i < CMF_ROWS {
        s += CIE_1931_2DEG[i][1];
        i += 1;
    }
    s
};

/// ∫ ȳ(λ) dλ over 360–830 nm (the 1 nm Riemann sum of the table,
/// ≈ 106.856917), the factor that makes a constant unit spectrum have Y = 1.
pub const CIE_Y_INTEGRAL: f32 = Y_SUM as f32;

/// D65 (relative, 100 at 560 nm) at an integer wavelength, linear between
/// the 5 nm entries; 0 outside 300–830 nm.
pub(super) const fn d65_at_nm(nm: usize) -> f64 {
    if nm < D65_FIRST_NM {
        return 0.0;
    }
    let off = nm - D65_FIRST_NM;
    let i = off / D65_STEP_NM;
    let r = off % D65_STEP_NM;
    if i + 1 >= CIE_D65.len() {
        return if r == 0 && i < CIE_D65.len() {
            CIE_D65[i]
        } else {
            0.0
        };
    }
    let f = r as f64 / D65_STEP_NM as f64;
    CIE_D65[i] * (1.0 - f) + CIE_D65[i + 1] * f
}

/// Σ D65·ȳ at 1 nm: the Y of the D65 table, used to scale reflectance
/// integrals so the perfect white reflector has Y = 1.
pub(super) const D65_Y_SUM: f64 = {
    let mut s = 0.0;
    let mut i = 0;
    while i < CMF_ROWS {
        s += d65_at_nm(CMF_FIRST_NM + i) * CIE_1931_2DEG[i][1];
        i += 1;
    }
    s
};

/// x̄ ȳ z̄ at 360 + `row` nm, f64.
pub(super) fn cmf_row(row: usize) -> [f64; 3] {
    CIE_1931_2DEG[row]
}

/// The tables in f32 for the per-path lookups: f32 holds them to 6·10⁻⁸ relative, far below
/// the tables' own precision, and spares two conversions per entry on every path.
pub(super) static CMF_F32: [[f32; 3]; CMF_ROWS] = {
    let mut t = [[0.0f32; 3]; CMF_ROWS];
    let mut i = 0;
    while i < CMF_ROWS {
        let r = CIE_1931_2DEG[i];
        t[i] = [r[0] as f32, r[1] as f32, r[2] as f32];
        i += 1;
    }
    t
};
static D65_F32: [f32; CIE_D65.len()] = {
    let mut t = [0.0f32; CIE_D65.len()];
    let mut i = 0;
    while i < CIE_D65.len() {
        t[i] = CIE_D65[i] as f32;
        i += 1;
    }
    t
};

/// CIE 1931 2° colour matching functions (x̄, ȳ, z̄) at `lambda` nm,
/// linear between the 1 nm entries; zero outside 360–830 nm.
#[inline(always)]
pub fn cie_xyz(lambda: f32) -> Vec3 {
    let x = lambda - CMF_FIRST_NM as f32;
    if !(x >= 0.0 && x <= (CMF_ROWS - 1) as f32) {
        return Vec3::ZERO;
    }
    // Through i32: x is in range, and a float → usize cast costs a dozen instructions on x86.
    let i = (x as i32 as usize).min(CMF_ROWS - 2);
    let f = x - i as f32;
    let (a, b) = (
        Vec3::from_array(CMF_F32[i]),
        Vec3::from_array(CMF_F32[i + 1]),
    );
    a + (b - a) * f
}

/// CIE standard illuminant D65, relative spectral power (100 at 560 nm),
/// linear between the 5 nm table entries; zero outside 300–830 nm.
#[inline(always)]
pub fn d65(lambda: f32) -> f32 {
    let x = (lambda - D65_FIRST_NM as f32) * (1.0 / D65_STEP_NM as f32);
    if !(x >= 0.0 && x <= (D65_F32.len() - 1) as f32) {
        return 0.0;
    }
    let i = (x as usize).min(D65_F32.len() - 2);
    let f = x - i as f32;
    D65_F32[i] + (D65_F32[i + 1] - D65_F32[i]) * f
}

/// Monte Carlo estimate of XYZ from one path's spectral sample:
/// Σᵢ Lᵢ·cmf(λᵢ)/pdfᵢ / (N · [`CIE_Y_INTEGRAL`]).
///
/// Terminated wavelengths (pdf 0) contribute nothing; see
/// [`Wavelengths::terminate_secondary`] for why the sum still divides by N.
/// Dividing by the ȳ integral makes a constant spectrum of 1 give Y = 1.
#[inline(always)]
pub fn to_xyz(l: &SampledSpectrum, w: &Wavelengths) -> Vec3 {
    let mut xyz = Vec3::ZERO;
    for i in 0..N_LAMBDA {
        if w.pdf[i] != 0.0 {
            xyz += cie_xyz(w.lambda[i]) * (l.0[i] / w.pdf[i]);
        }
    }
    xyz / (N_LAMBDA as f32 * CIE_Y_INTEGRAL)
}

/// XYZ of an emission spectrum `f` (1 nm quadrature over 360–830 nm),
/// scaled like [`to_xyz`] so a constant 1 has Y = 1.
pub fn spectrum_to_xyz(f: impl Fn(f32) -> f32) -> Vec3 {
    let mut s = [0.0f64; 3];
    for (row, cmf) in CIE_1931_2DEG.iter().enumerate() {
        let v = f64::from(f((CMF_FIRST_NM + row) as f32));
        for k in 0..3 {
            s[k] += v * cmf[k];
        }
    }
    Vec3::new(s[0] as f32, s[1] as f32, s[2] as f32) / Y_SUM as f32
}

/// Luminance Y (∫ f ȳ / [`CIE_Y_INTEGRAL`]) of an emission spectrum.
pub fn luminance(f: impl Fn(f32) -> f32) -> f32 {
    let s: f64 = CIE_1931_2DEG
        .iter()
        .enumerate()
        .map(|(row, cmf)| f64::from(f((CMF_FIRST_NM + row) as f32)) * cmf[1])
        .sum();
    (s / Y_SUM) as f32
}

/// XYZ of a reflectance spectrum `f` lit by D65, scaled so the perfect
/// white reflector has Y = 1 (the colour an albedo shows under the sRGB
/// white point).
pub fn reflectance_to_xyz(f: impl Fn(f32) -> f32) -> Vec3 {
    let mut s = [0.0f64; 3];
    for (row, cmf) in CIE_1931_2DEG.iter().enumerate() {
        let nm = CMF_FIRST_NM + row;
        let v = f64::from(f(nm as f32)) * d65_at_nm(nm);
        for k in 0..3 {
            s[k] += v * cmf[k];
        }
    }
    Vec3::new(s[0] as f32, s[1] as f32, s[2] as f32) / D65_Y_SUM as f32
}

/// Chromaticity (x, y) of an XYZ colour; (0, 0) for black.
pub fn xyz_to_chromaticity(xyz: Vec3) -> Vec2 {
    let s = xyz.x + xyz.y + xyz.z;
    if s == 0.0 {
        Vec2::ZERO
    } else {
        Vec2::new(xyz.x / s, xyz.y / s)
    }
}

/// Linear sRGB → XYZ, derived from the IEC 61966-2-1 primaries
/// (0.64, 0.33), (0.30, 0.60), (0.15, 0.06) and D65 white (0.3127, 0.3290)
/// at full precision rather than the standard's 4-digit rounding, so the
/// matrix and its inverse are exact inverses.
pub const SRGB_TO_XYZ: Mat3 = Mat3::from_cols(
    Vec3::new(0.412_390_8, 0.212_639, 0.019_330_8),
    Vec3::new(0.357_584_3, 0.715_168_7, 0.119_194_8),
    Vec3::new(0.180_480_8, 0.072_192_3, 0.950_532_2),
);

/// XYZ → linear sRGB, the inverse of [`SRGB_TO_XYZ`].
pub const XYZ_TO_SRGB: Mat3 = Mat3::from_cols(
    Vec3::new(3.240_97, -0.969_243_6, 0.055_630_1),
    Vec3::new(-1.537_383_2, 1.875_967_5, -0.203_977),
    Vec3::new(-0.498_610_8, 0.041_555_1, 1.056_971_5),
);

/// The linear sRGB matching functions, [`XYZ_TO_SRGB`] · (x̄, ȳ, z̄) per 1 nm row, divided by
/// N · [`CIE_Y_INTEGRAL`] (the other factors of [`to_xyz`]), the fourth entry zero: one aligned
/// load per table row turns a path's spectral sample into the film's colour.
static RGB_BAR: [glam::Vec4; CMF_ROWS] = {
    let m = XYZ_TO_SRGB;
    let rows = [
        [m.x_axis.x as f64, m.y_axis.x as f64, m.z_axis.x as f64],
        [m.x_axis.y as f64, m.y_axis.y as f64, m.z_axis.y as f64],
        [m.x_axis.z as f64, m.y_axis.z as f64, m.z_axis.z as f64],
    ];
    let norm = 1.0 / (N_LAMBDA as f64 * Y_SUM);
    let mut t = [glam::Vec4::ZERO; CMF_ROWS];
    let mut i = 0;
    while i < CMF_ROWS {
        let c = CIE_1931_2DEG[i];
        let mut v = [0.0f32; 3];
        let mut r = 0;
        while r < 3 {
            let x = rows[r][0] * c[0] + rows[r][1] * c[1] + rows[r][2] * c[2];
            v[r] = (x * norm) as f32;
            r += 1;
        }
        t[i] = glam::Vec4::new(v[0], v[1], v[2], 0.0);
        i += 1;
    }
    t
};

/// Linear sRGB of one path's spectral sample: [`xyz_to_linear_srgb`] of [`to_xyz`], in one
/// pass over a table of the sRGB matching functions (the matrix folded into the table, so it
/// differs from the two-step form only by rounding). Terminated wavelengths (pdf 0) and
/// wavelengths outside the table contribute nothing.
#[inline(always)]
pub fn to_linear_srgb(l: [f32; N_LAMBDA], lambda: [f32; N_LAMBDA], pdf: [f32; N_LAMBDA]) -> Vec3 {
    let mut rgb = glam::Vec4::ZERO;
    for k in 0..N_LAMBDA {
        let x = lambda[k] - CMF_FIRST_NM as f32;
        if pdf[k] != 0.0 && x >= 0.0 && x <= (CMF_ROWS - 1) as f32 {
            // Through i32: x is in range, and a float → usize cast costs a dozen instructions.
            let i = (x as i32 as usize).min(CMF_ROWS - 2);
            let f = x - i as f32;
            let (a, b) = (RGB_BAR[i], RGB_BAR[i + 1]);
            rgb += (a + (b - a) * f) * (l[k] / pdf[k]);
        }
    }
    rgb.truncate()
}

/// CIE XYZ → linear sRGB (D65 white: XYZ (0.9505, 1, 1.089) → (1, 1, 1)).
#[inline(always)]
pub fn xyz_to_linear_srgb(xyz: Vec3) -> Vec3 {
    XYZ_TO_SRGB * xyz
}

/// Linear sRGB → CIE XYZ.
pub fn linear_srgb_to_xyz(rgb: Vec3) -> Vec3 {
    SRGB_TO_XYZ * rgb
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_pass_srgb_matches_xyz_then_matrix() {
        // The folded table against the two-step form: equal up to f32 rounding of a sum of
        // four terms and a 3×3 product (a few ulps of the largest term).
        let mut rng = 0x2545_f491_u32;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            rng as f32 / u32::MAX as f32
        };
        for case in 0..20_000 {
            let mut w = Wavelengths::sample_visible(next());
            if case % 7 == 0 {
                w.terminate_secondary();
            }
            let l = SampledSpectrum(std::array::from_fn(|_| next() * 4.0));
            let want = xyz_to_linear_srgb(to_xyz(&l, &w));
            let got = to_linear_srgb(l.0, w.lambda, w.pdf);
            let scale = (0..N_LAMBDA)
                .filter(|&k| w.pdf[k] != 0.0)
                .map(|k| l.0[k] / w.pdf[k] / (N_LAMBDA as f32 * CIE_Y_INTEGRAL))
                .fold(0.0f32, f32::max)
                * 4.0;
            let err = (got - want).abs().max_element();
            assert!(err <= 1e-5 * scale + 1e-12, "{w:?} {l:?}: {got} vs {want}");
        }
        // Outside the table and terminated wavelengths add nothing.
        let w = Wavelengths {
            lambda: [300.0, 900.0, 550.0, f32::NAN],
            pdf: [1.0, 1.0, 0.0, 1.0],
        };
        assert_eq!(to_linear_srgb([1.0; 4], w.lambda, w.pdf), Vec3::ZERO);
    }

    #[test]
    fn srgb_matrices_follow_from_the_primaries() {
        // Columns of RGB→XYZ are the primaries' XYZ scaled so R+G+B = white.
        let xyz = |x: f64, y: f64| [x / y, 1.0, (1.0 - x - y) / y];
        let p = [xyz(0.64, 0.33), xyz(0.30, 0.60), xyz(0.15, 0.06)];
        let w = xyz(0.3127, 0.3290);
        let m = glam::DMat3::from_cols(p[0].into(), p[1].into(), p[2].into());
        let s = m.inverse() * glam::DVec3::from(w);
        let exact = glam::DMat3::from_cols(m.x_axis * s.x, m.y_axis * s.y, m.z_axis * s.z);
        let ours = SRGB_TO_XYZ.as_dmat3();
        let inv = XYZ_TO_SRGB.as_dmat3();
        for c in 0..3 {
            for r in 0..3 {
                assert!((exact.col(c)[r] - ours.col(c)[r]).abs() < 1e-6);
                assert!((exact.inverse().col(c)[r] - inv.col(c)[r]).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn d65_interpolation_hits_the_table() {
        assert_eq!(d65(560.0), 100.0);
        assert_eq!(d65(300.0), 0.0341);
        assert_eq!(d65(830.0), 60.3125);
        assert_eq!(d65(831.0), 0.0);
        assert!((d65(562.0) - (100.0 * 0.6 + 98.1671 * 0.4)).abs() < 1e-4);
        assert_eq!(d65_at_nm(830), 60.3125);
        assert_eq!(d65_at_nm(831), 0.0);
        assert!((d65_at_nm(562) - f64::from(d65(562.0))).abs() < 1e-4);
    }

    #[test]
    fn cmf_edges() {
        assert_eq!(cie_xyz(359.9), Vec3::ZERO);
        assert_eq!(cie_xyz(830.1), Vec3::ZERO);
        assert!(cie_xyz(830.0).y > 0.0 && cie_xyz(360.0).x > 0.0);
        assert_eq!(cie_xyz(f32::NAN), Vec3::ZERO);
    }
}
