//! The image channels a render writes (docs/design.md §1.6) and their statistics over the
//! object pixels: what a channel is, its values from the Stokes image, and the summary numbers.

use crate::render::film::{dolp_aop, polarizer, StokesImage, BACKGROUND};
use serde::Serialize;

/// The image channels written (docs/design.md §1.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    S0,
    S1,
    S2,
    S3,
    Dolp,
    Aop,
    I0,
    I45,
    I90,
    I135,
}

impl Channel {
    pub const ALL: [Channel; 10] = [
        Channel::S0,
        Channel::S1,
        Channel::S2,
        Channel::S3,
        Channel::Dolp,
        Channel::Aop,
        Channel::I0,
        Channel::I45,
        Channel::I90,
        Channel::I135,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Channel::S0 => "S0",
            Channel::S1 => "S1",
            Channel::S2 => "S2",
            Channel::S3 => "S3",
            Channel::Dolp => "DoLP",
            Channel::Aop => "AoP",
            Channel::I0 => "I0",
            Channel::I45 => "I45",
            Channel::I90 => "I90",
            Channel::I135 => "I135",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            Channel::Dolp => "1",
            Channel::Aop => "rad",
            _ => "W m-2 sr-1",
        }
    }

    /// Which of I0, I45, I90, I135 the channel is, if a polarizer image.
    pub fn polarizer_index(self) -> Option<usize> {
        match self {
            Channel::I0 => Some(0),
            Channel::I45 => Some(1),
            Channel::I90 => Some(2),
            Channel::I135 => Some(3),
            _ => None,
        }
    }

    /// The channel's value for a pixel-frame Stokes vector.
    #[inline]
    pub fn value(self, s: [f64; 4]) -> f64 {
        use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
        match self {
            Channel::S0 => s[0],
            Channel::S1 => s[1],
            Channel::S2 => s[2],
            Channel::S3 => s[3],
            Channel::Dolp => dolp_aop(s).0,
            Channel::Aop => dolp_aop(s).1,
            Channel::I0 => polarizer(s, 0.0),
            Channel::I45 => polarizer(s, FRAC_PI_4),
            Channel::I90 => polarizer(s, FRAC_PI_2),
            Channel::I135 => polarizer(s, 3.0 * FRAC_PI_4),
        }
    }
}

impl StokesImage {
    /// One channel as 32-bit floats, row-major from the top. The polarizer images are the
    /// recorded (noisy) ones when the sensor has noise, not re-derived from the Stokes estimate.
    pub fn channel(&self, channel: Channel) -> Vec<f32> {
        if let (Some(k), false) = (
            channel.polarizer_index(),
            self.recorded_polarizers.is_empty(),
        ) {
            return self.recorded_polarizers.iter().map(|i| i[k]).collect();
        }
        self.stokes
            .iter()
            .map(|&s| channel.value(s) as f32)
            .collect()
    }

    /// Minimum, maximum and mean of a channel over the object pixels (None without any).
    pub fn object_stats(&self, values: &[f32]) -> Option<Stats> {
        let mut stats = Stats {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            mean: 0.0,
        };
        let mut count = 0usize;
        for (&v, &o) in values.iter().zip(&self.surface) {
            if o != BACKGROUND {
                let v = v as f64;
                stats.min = stats.min.min(v);
                stats.max = stats.max.max(v);
                stats.mean += v;
                count += 1;
            }
        }
        (count > 0).then(|| Stats {
            mean: stats.mean / count as f64,
            ..stats
        })
    }
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct Stats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct ErrorSummary {
    pub mean: f64,
    pub median: f64,
    pub p99: f64,
}

impl StokesImage {
    /// Mean, median and 99th percentile of the standard error of Stokes component `j` relative to S0,
    /// over object pixels with S0 > 0.
    pub fn relative_error(&self, j: usize) -> Option<ErrorSummary> {
        let mut values: Vec<f64> = self
            .stokes
            .iter()
            .zip(&self.standard_error)
            .zip(&self.surface)
            .filter(|((s, _), &o)| o != BACKGROUND && s[0] > 0.0)
            .map(|((s, e), _)| e[j] / s[0])
            .filter(|v| v.is_finite())
            .collect();
        if values.is_empty() {
            return None;
        }
        values.sort_by(f64::total_cmp);
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let quantile = |p: f64| values[((values.len() - 1) as f64 * p).round() as usize];
        Some(ErrorSummary {
            mean,
            median: quantile(0.5),
            p99: quantile(0.99),
        })
    }
}
