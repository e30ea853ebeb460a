//! The sRGB transfer function (IEC 61966-2-1) in both directions.

/// sRGB opto-electronic transfer function (IEC 61966-2-1), linear → encoded.
///
/// Values at or below the 0.0031308 breakpoint (including negatives) take
/// the linear segment, so the result is never NaN for finite input.
pub fn srgb_encode(linear: f32) -> f32 {
    // Branch on the f32 value so an input of exactly `0.0031308_f32` is on
    // the linear segment (widened to f64 it is slightly larger); evaluate in
    // f64 to keep the round trip with `srgb_decode` well inside 1e-6.
    let l = f64::from(linear);
    let e = if linear <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    e as f32
}

/// Inverse of [`srgb_encode`], encoded → linear, breakpoint 0.04045.
pub fn srgb_decode(encoded: f32) -> f32 {
    let e = f64::from(encoded);
    let l = if encoded <= 0.040_45 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    };
    l as f32
}
