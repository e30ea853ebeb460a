//! Writes `src/integrator/dielectric_energy.bin`: the energy tables of the rough dielectric's
//! multiple-scattering compensation (`prism::energy::dielectric_energy_table`), as 16-bit
//! little-endian fixed point.
//!
//! `cargo run --release --example dielectric_tables`

use prism::energy::{DIELECTRIC_GRID, dielectric_energy_table};

fn main() -> std::io::Result<()> {
    let t = dielectric_energy_table(DIELECTRIC_GRID);
    let bytes: Vec<u8> = t.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write("src/integrator/dielectric_energy.bin", bytes)
}
