//! The `[render]` section checked (docs/design.md §2.4): how light reaches the visible points and
//! how previews are scaled. (Kept with the scene rather than in `transport`, which reads the
//! scene: the settings are what the scene asks of it.)

use super::config::{PreviewConfig, RenderConfig};
use super::SceneError;
use std::path::Path;

/// Monte Carlo settings of the path integrator (`[render]`, docs/design.md §2.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct PathSettings {
    /// Vertex k (0 = the camera's visible point) traces its correction while k ≤ `bounces`:
    /// 0 still occludes the visible point's environment (a blocked direction delivers the
    /// blocker's open-world value); 3 follows three inter-reflections.
    pub bounces: u32,
    /// Paths per pixel.
    pub samples: u32,
    /// Lobe samples per path at the visible point: the path's own continues, the others take
    /// their hit's open-world value (1: no split; [`crate::transport`]'s path integrator).
    pub first_bounce_samples: u32,
    pub seed: u64,
}

/// How light reaches the visible points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// The paper's model (docs/design.md §1.5): every point sees the whole sky and ground; no sun.
    OpenWorld,
    /// Occlusion, inter-reflection and the sun (docs/design.md §1.7).
    Path(PathSettings),
}

/// Deeper chains change nothing measurable in thermal scenes (each bounce multiplies by a
/// reflectance well below 1) and only cost time.
const MAX_BOUNCES: u32 = 64;

/// A split beyond this costs more first-bounce rays than the deeper paths it shares them with
/// can use.
const MAX_FIRST_BOUNCE_SAMPLES: u32 = 64;

/// The `[render]` transport keys, checked.
pub(super) fn transport_settings(
    path: &Path,
    render: &RenderConfig,
) -> Result<Transport, SceneError> {
    if render.open_world {
        return Ok(Transport::OpenWorld);
    }
    if render.samples == 0 {
        return Err(SceneError::new(
            path,
            "render.samples = 0: give at least 1 path per pixel (or open_world = true)",
        ));
    }
    if render.bounces > MAX_BOUNCES {
        return Err(SceneError::new(
            path,
            format!(
                "render.bounces = {} is more than {MAX_BOUNCES}",
                render.bounces
            ),
        ));
    }
    if !(1..=MAX_FIRST_BOUNCE_SAMPLES).contains(&render.first_bounce_samples) {
        return Err(SceneError::new(
            path,
            format!(
                "render.first_bounce_samples = {} must lie within 1..={MAX_FIRST_BOUNCE_SAMPLES}",
                render.first_bounce_samples
            ),
        ));
    }
    Ok(Transport::Path(PathSettings {
        bounces: render.bounces,
        samples: render.samples,
        first_bounce_samples: render.first_bounce_samples,
        seed: render.seed,
    }))
}

/// `[render.preview]`: percentiles within [0, 100] and increasing, fixed ranges finite and
/// increasing.
pub(super) fn checked_preview(
    path: &Path,
    preview: &PreviewConfig,
) -> Result<PreviewConfig, SceneError> {
    let pairs = [
        ("percentiles", preview.percentiles),
        ("s0_k", preview.s0_k),
        ("s1", preview.s1),
        ("s2", preview.s2),
        ("s3", preview.s3),
        ("dolp_percent", preview.dolp_percent),
    ];
    for (key, pair) in pairs {
        if let Some([lo, hi]) = pair {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(SceneError::new(
                    path,
                    format!(
                    "render.preview.{key} = [{lo}, {hi}] must be two finite numbers, low < high"
                ),
                ));
            }
        }
    }
    if let Some([lo, hi]) = preview.percentiles {
        if lo < 0.0 || hi > 100.0 {
            return Err(SceneError::new(
                path,
                format!("render.preview.percentiles = [{lo}, {hi}] must lie within [0, 100]"),
            ));
        }
    }
    Ok(preview.clone())
}
