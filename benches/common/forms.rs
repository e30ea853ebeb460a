//! The lane forms a bench compares: one lane, the portable 8-lane reference, and the native
//! widths this CPU runs.

use prism::simd::Lanes;

pub fn forms() -> Vec<(String, Lanes)> {
    let mut v = vec![
        ("w1".to_string(), Lanes::scalar()),
        ("portable8".to_string(), Lanes::portable(8)),
    ];
    if let Some(l) = Lanes::native8() {
        v.push(("w8".to_string(), l));
    }
    if let Some(l) = Lanes::native16() {
        v.push(("w16".to_string(), l));
    }
    v
}
