//! How a linear panel is coloured: its display range (fixed, or robust percentiles of the
//! ranged pixels reaching past them to take in noise), each pixel's colour, and the clip stated
//! in the title.

use super::{Bar, Clipped, LinearPanel, Panel};
use crate::output::colormap::{Lut, MASKED};
use crate::scene::config::{PreviewConfig, PreviewRange};
use rayon::prelude::*;

/// Default percentile range of the previews: wide enough that a hot hood or a strongly
/// polarizing windshield (a few % of the pixels) stays inside the colour bar, narrow enough that
/// a handful of glint or noise pixels does not wash the image out; what falls outside is drawn in
/// the map's under/over colours and counted in the title.
const DEFAULT_PERCENTILES: [f64; 2] = [0.1, 99.9];

/// How far past the default percentiles (a fraction of their distance) the range reaches to
/// take in the values just beyond them. Pure Gaussian noise (a flat scene under NETD) has its
/// 0.1/99.9 % points at ±3.09σ and its extremes near ±4.9σ over a megapixel, ±5.3σ over ten:
/// 0.4 × 6.18σ reaches ±5.56σ, so noise alone is not drawn clipped.
const DEFAULT_MARGIN: f64 = 0.4;

impl LinearPanel {
    /// The panel: its range (fixed, else by `settings.range` over the `ranged` pixels), each
    /// pixel's colour, ranged pixels out of range in the map's under/over colours, the clip
    /// stated in the title.
    pub(super) fn panel(self, ranged: &[bool], settings: &PreviewConfig) -> Panel {
        let range = self.range(self.ranging_values(ranged).collect(), settings);
        self.coloured(ranged, range)
    }

    /// The values of the `ranged` pixels that set an automatic range (|value| when symmetric).
    pub(super) fn ranging_values<'a>(
        &'a self,
        ranged: &'a [bool],
    ) -> impl Iterator<Item = f64> + 'a {
        self.values
            .iter()
            .zip(ranged)
            .filter(|&(v, &r)| r && v.is_finite())
            .map(|(&v, _)| if self.symmetric { v.abs() } else { v })
    }

    /// The display range: fixed, or automatic over `chosen` ([`Self::ranging_values`], of one
    /// image or of a whole time series).
    pub(super) fn range(&self, chosen: Vec<f64>, settings: &PreviewConfig) -> (f64, f64) {
        let auto = || {
            let (percentiles, margin) = match (settings.range, settings.percentiles) {
                (PreviewRange::Minmax, _) => ([0.0, 100.0], 0.0),
                (PreviewRange::Percentile, Some(given)) => (given, 0.0),
                (PreviewRange::Percentile, None) => (DEFAULT_PERCENTILES, DEFAULT_MARGIN),
            };
            let [p_lo, p_hi] = percentiles;
            let p_lo = if self.symmetric { 0.0 } else { p_lo };
            robust_range(chosen, p_lo / 100.0, p_hi / 100.0, margin)
        };
        let (lo, hi) = match self.fixed {
            // DoLP's default: from 0 to the automatic high end.
            Some([lo, hi]) if hi.is_nan() => (lo, auto().1),
            Some([lo, hi]) => (lo, hi),
            None if self.symmetric => {
                let m = auto().1;
                let m = if m > 0.0 { m } else { 1.0 };
                (-m, m)
            }
            None => auto(),
        };
        widen(lo, hi)
    }

    /// The panel coloured over `(lo, hi)`. A ranged pixel outside it takes the map's under/over
    /// colour and is counted in the title; the others (sky and the environment's ground beside
    /// objects, which do not set the range) take the map's end colour: a sky colder than every
    /// object is the map's cold end, not an alarm.
    pub(super) fn coloured(self, ranged: &[bool], (lo, hi): (f64, f64)) -> Panel {
        let lut = Lut::new(self.map);
        let colors: Vec<[u8; 3]> = self
            .values
            .par_iter()
            .zip(ranged)
            .map(|(&v, &r)| match v {
                v if v.is_nan() => MASKED,
                v if v < lo && r => self.map.under,
                v if v > hi && r => self.map.over,
                v if v < lo => lut.at(0.0),
                v if v > hi => lut.at(1.0),
                v => lut.at((v - lo) / (hi - lo)),
            })
            .collect();
        let ranged_count = ranged.iter().filter(|&&r| r).count().max(1) as f64;
        let count = |f: &dyn Fn(f64) -> bool| {
            self.values
                .iter()
                .zip(ranged)
                .filter(|&(&v, &r)| r && f(v))
                .count() as f64
                / ranged_count
        };
        let clipped = Clipped {
            below: count(&|v| v < lo),
            above: count(&|v| v > hi),
        };
        let mut title = self.title;
        let sides: Vec<String> = [(clipped.below, "below"), (clipped.above, "above")]
            .iter()
            .filter(|(fraction, _)| *fraction > 0.0)
            .map(|(fraction, side)| format!("{} {side}", percent(*fraction)))
            .collect();
        if !sides.is_empty() {
            title += &format!(" — pixels clipped: {}", sides.join(", "));
        }
        Panel {
            file: self.file,
            title,
            colors,
            bar: Bar::Linear {
                map: self.map,
                lo,
                hi,
                signed: self.symmetric,
                clipped,
            },
        }
    }
}

/// A clipped fraction (> 0) as a percentage: one decimal, but never "0.0 %" for a few pixels.
fn percent(fraction: f64) -> String {
    match 100.0 * fraction {
        p if p < 0.05 => "< 0.1 %".into(),
        p => format!("{p:.1} %"),
    }
}

/// (p_lo, p_hi) quantiles of the values (0, 1 when empty), each moved out by `margin` times
/// their distance but not past the values' own extremes: noise that straddles a cut-off stays in
/// range (it would paint speckle in the under/over colours), outliers far beyond it do not.
pub(super) fn robust_range(mut values: Vec<f64>, p_lo: f64, p_hi: f64, margin: f64) -> (f64, f64) {
    if values.is_empty() {
        return (0.0, 1.0);
    }
    let mut quantile = |p: f64| {
        let k = ((values.len() - 1) as f64 * p).round() as usize;
        *values.select_nth_unstable_by(k, f64::total_cmp).1
    };
    let (lo, hi) = (quantile(p_lo), quantile(p_hi));
    if margin == 0.0 {
        return (lo, hi);
    }
    let (min, max) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let reach = margin * (hi - lo);
    ((lo - reach).max(min), (hi + reach).min(max))
}

/// A non-empty display range.
pub(super) fn widen(lo: f64, hi: f64) -> (f64, f64) {
    if hi - lo > 1e-6 {
        (lo, hi)
    } else {
        (lo - 0.5, hi + 0.5)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Bar, LinearPanel, Panel};
    use crate::output::colormap::THERMAL;
    use crate::scene::config::{PreviewConfig, PreviewRange};

    fn ramp_panel(fixed: Option<[f64; 2]>, range: PreviewRange) -> Panel {
        // 0, 1, …, 999 with every pixel ranged.
        let ranged = vec![true; 1000];
        let settings = PreviewConfig {
            range,
            ..PreviewConfig::default()
        };
        LinearPanel {
            file: "x.png",
            title: "x".into(),
            values: (0..1000).map(f64::from).collect(),
            fixed,
            symmetric: false,
            map: &THERMAL,
        }
        .panel(&ranged, &settings)
    }

    fn clipped(panel: &Panel) -> (f64, f64, f64, f64) {
        match &panel.bar {
            Bar::Linear {
                lo, hi, clipped, ..
            } => (*lo, *hi, clipped.below, clipped.above),
            Bar::Cyclic => unreachable!(),
        }
    }

    #[test]
    fn out_of_range_pixels_are_marked_and_counted() {
        let panel = ramp_panel(Some([100.0, 899.0]), PreviewRange::Percentile);
        assert_eq!(clipped(&panel), (100.0, 899.0, 0.1, 0.1));
        assert_eq!(panel.colors[50], THERMAL.under);
        assert_eq!(panel.colors[950], THERMAL.over);
        assert_eq!(panel.colors[100], THERMAL.at(0.0));
        assert!(
            panel
                .title
                .contains("pixels clipped: 10.0 % below, 10.0 % above"),
            "{}",
            panel.title
        );

        let minmax = ramp_panel(None, PreviewRange::Minmax);
        assert_eq!(clipped(&minmax), (0.0, 999.0, 0.0, 0.0));
        assert_eq!(minmax.title, "x");

        // The default percentiles (1 and 998) reach out to the ramp's ends: nothing clipped.
        let auto = ramp_panel(None, PreviewRange::Percentile);
        assert_eq!(clipped(&auto), (0.0, 999.0, 0.0, 0.0));
        assert_eq!(auto.title, "x");
    }

    /// `n` standard normal values (Box–Muller over a seeded generator).
    fn gaussian(n: usize, seed: u64) -> Vec<f64> {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let (u, v): (f64, f64) = (rng.random(), rng.random());
                (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
            })
            .collect()
    }

    fn panel_of(values: Vec<f64>, ranged: &[bool], settings: &PreviewConfig) -> Panel {
        LinearPanel {
            file: "S0.png",
            title: "S0".into(),
            values,
            fixed: None,
            symmetric: false,
            map: &THERMAL,
        }
        .panel(ranged, settings)
    }

    #[test]
    fn detector_noise_alone_is_not_drawn_clipped_but_a_glint_is() {
        // A flat 300 K scene with 20 mK of noise over a megapixel: its extremes lie beyond the
        // 0.1/99.9 % points, which used to paint ~2000 speckles in the under/over colours.
        let values: Vec<f64> = gaussian(1 << 20, 7)
            .into_iter()
            .map(|z| 300.0 + 0.02 * z)
            .collect();
        let ranged = vec![true; values.len()];
        let settings = PreviewConfig::default();
        let panel = panel_of(values.clone(), &ranged, &settings);
        let (lo, hi, below, above) = clipped(&panel);
        assert_eq!((below, above), (0.0, 0.0), "{lo} … {hi}");
        assert!(!panel.title.contains("clipped"), "{}", panel.title);

        // A glint of 20 pixels at 340 K is far beyond the noise: it is clipped and counted.
        let mut glinting = values;
        glinting[..20].fill(340.0);
        let panel = panel_of(glinting, &ranged, &settings);
        let (_, hi, below, above) = clipped(&panel);
        assert!(hi < 300.2 && below == 0.0 && above > 0.0, "{hi} {above}");
        assert_eq!(panel.colors[0], THERMAL.over);
        assert!(
            panel.title.ends_with(" — pixels clipped: < 0.1 % above"),
            "{}",
            panel.title
        );

        // Percentiles the scene gives are taken as they are.
        let given = PreviewConfig {
            percentiles: Some([5.0, 95.0]),
            ..PreviewConfig::default()
        };
        let ramp: Vec<f64> = (0..1000).map(f64::from).collect();
        let panel = panel_of(ramp, &[true; 1000], &given);
        assert_eq!(clipped(&panel), (50.0, 949.0, 0.05, 0.05));
    }

    #[test]
    fn sky_outside_the_range_takes_the_maps_end_colour_and_is_not_counted_as_clipped() {
        // Objects at 290…300 K in the first 100 pixels, a 230 K sky and a 320 K patch of the
        // environment's ground in the others: neither sets the range nor is drawn as a clip.
        let mut values: Vec<f64> = (0..100).map(|i| 290.0 + 0.1 * f64::from(i)).collect();
        values.extend([230.0; 50]);
        values.extend([320.0; 50]);
        let ranged: Vec<bool> = (0..200).map(|i| i < 100).collect();
        let panel = panel_of(values, &ranged, &PreviewConfig::default());
        let (lo, hi, below, above) = clipped(&panel);
        assert_eq!((lo, hi, below, above), (290.0, 299.9, 0.0, 0.0));
        assert_eq!(panel.colors[120], THERMAL.at(0.0));
        assert_eq!(panel.colors[170], THERMAL.at(1.0));
        assert!(!panel.title.contains("clipped"), "{}", panel.title);
    }
}
