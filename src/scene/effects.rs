//! The effects manifest: which optional parts of light transport a render simulates
//! (found by `systems::detect_effects`).

use std::fmt;

/// One optional effect of the renderer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Effect {
    /// Depth of field: camera rays start on a thin lens.
    Lens,
    /// Motion blur: moving entities or a camera moving within the shutter.
    Motion,
    /// Spectral transport at hero wavelengths instead of RGB.
    Spectral,
    /// Participating media: scattering and absorption between surfaces.
    Media,
    /// Albedo textures modulate material colours.
    Textures,
    /// Normal maps perturb shading normals.
    NormalMaps,
}

impl Effect {
    /// Every effect, in manifest order.
    pub const ALL: [Effect; 6] = [
        Effect::Lens,
        Effect::Motion,
        Effect::Spectral,
        Effect::Media,
        Effect::Textures,
        Effect::NormalMaps,
    ];

    /// The name in the manifest and in messages, e.g. `NORMAL_MAPS`.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Lens => "LENS",
            Effect::Motion => "MOTION",
            Effect::Spectral => "SPECTRAL",
            Effect::Media => "MEDIA",
            Effect::Textures => "TEXTURES",
            Effect::NormalMaps => "NORMAL_MAPS",
        }
    }

    /// Parses `--force` values: `lens`, `motion`, `spectral`, `media`, `textures`,
    /// `normal_maps` (any case, `-` or `_`).
    pub fn parse(s: &str) -> Option<Effect> {
        let k = s.to_ascii_uppercase().replace('-', "_");
        Effect::ALL.into_iter().find(|e| e.name() == k)
    }

    /// Whether this build can simulate the effect at all.
    pub fn implemented(self) -> bool {
        true
    }
}

/// The set of effects a render simulates, with the reason each is on or off.
#[derive(Clone, Debug, Default)]
pub struct Effects {
    on: [bool; 6],
    reasons: [String; 6],
}

impl Effects {
    /// Whether the effect is on.
    pub fn has(&self, e: Effect) -> bool {
        self.on[e as usize]
    }

    /// Turns the effect on or off, with the reason the manifest prints.
    pub fn set(&mut self, e: Effect, on: bool, reason: impl Into<String>) {
        self.on[e as usize] = on;
        self.reasons[e as usize] = reason.into();
    }

    /// Why the effect is on or off.
    pub fn reason(&self, e: Effect) -> &str {
        &self.reasons[e as usize]
    }

    /// Turns an effect on although the scene does not need it (`--force`), for measuring
    /// its cost and checking that it changes nothing beyond noise.
    pub fn force(&mut self, e: Effect) -> Result<(), String> {
        if !e.implemented() {
            return Err(format!(
                "--force {}: this build does not simulate {} yet",
                e.name().to_ascii_lowercase(),
                e.name()
            ));
        }
        if !self.has(e) {
            self.set(e, true, "forced by --force");
        }
        Ok(())
    }
}

impl fmt::Display for Effects {
    /// The manifest: one line per effect, `NAME: on|off (reason)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for e in Effect::ALL {
            writeln!(
                f,
                "{}: {} ({})",
                e.name(),
                if self.has(e) { "on" } else { "off" },
                self.reason(e)
            )?;
        }
        Ok(())
    }
}
