//! Ma et al. (2009) Figs. 2 and 3: f00 against detector zenith in the plane of incidence for
//! θ_i = 60°, λ = 9.925 µm, N = 1.2 + 0.2i — Fig. 2 at σ = 0.1 for q = 1.5, 1.8, 2.5, Fig. 3 at
//! q = 1.8 for σ = 0.1, 0.2, 0.3. Drawn with G = 1 (shadowing none), as the paper's eq. 4 curves.

use super::ReportError;
use crate::atomic::write_atomically;
use crate::optics::RefractiveIndex;
use crate::pbrdf::{Direction, Pbrdf, Shadowing, SlopeDistribution};
use crate::plot_style::{encode_png, register_fonts, FONT};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PaperFigure {
    /// f00 for q = 1.5, 1.8, 2.5 at σ = 0.1.
    Fig2,
    /// f00 for σ = 0.1, 0.2, 0.3 at q = 1.8.
    Fig3,
}

impl PaperFigure {
    pub fn file_stem(&self) -> &'static str {
        match self {
            PaperFigure::Fig2 => "paper-fig2",
            PaperFigure::Fig3 => "paper-fig3",
        }
    }

    /// (legend label, σ, q) of each curve.
    fn curves(&self) -> Vec<(String, f64, f64)> {
        match self {
            PaperFigure::Fig2 => [1.5, 1.8, 2.5]
                .iter()
                .map(|&q| (format!("q = {q}"), 0.1, q))
                .collect(),
            PaperFigure::Fig3 => [0.1, 0.2, 0.3]
                .iter()
                .map(|&s| (format!("σ = {s}"), s, 1.8))
                .collect(),
        }
    }

    fn title(&self) -> &'static str {
        match self {
            PaperFigure::Fig2 => "f00 vs detector zenith, σ = 0.1 (Ma et al. 2009, Fig. 2)",
            PaperFigure::Fig3 => "f00 vs detector zenith, q = 1.8 (Ma et al. 2009, Fig. 3)",
        }
    }
}

/// Detector zenith in the plane of incidence: positive on the specular side (φ_r = φ_i + 180°),
/// negative toward the source (φ_r = φ_i).
fn in_plane_f00(model: &Pbrdf, theta_i_deg: f64, detector_deg: f64) -> f64 {
    let incident = Direction::from_angles(theta_i_deg.to_radians(), 0.0);
    let phi_r = if detector_deg >= 0.0 {
        std::f64::consts::PI
    } else {
        0.0
    };
    let scattered = Direction::from_angles(detector_deg.abs().to_radians(), phi_r);
    model.first_column(&incident, &scattered)[0]
}

/// A labelled curve of (detector zenith °, f00 sr⁻¹).
pub type Curve = (String, Vec<(f64, f64)>);

/// The figure's curves.
pub fn figure_data(figure: PaperFigure) -> Result<Vec<Curve>, ReportError> {
    let index = RefractiveIndex::new(1.2, 0.2);
    figure
        .curves()
        .into_iter()
        .map(|(label, sigma, q)| {
            let model = Pbrdf::new(
                SlopeDistribution::Cauchy { sigma, q },
                Shadowing::None,
                index,
                0.0,
            )?;
            let points = (-890..=890)
                .step_by(5)
                .map(|tenth| {
                    let zenith = tenth as f64 / 10.0;
                    (zenith, in_plane_f00(&model, 60.0, zenith))
                })
                .collect();
            Ok((label, points))
        })
        .collect()
}

/// Writes `<out>/<stem>.png` and `.svg`; returns their paths.
pub fn write_paper_figure(
    figure: PaperFigure,
    out_dir: &Path,
) -> Result<Vec<PathBuf>, ReportError> {
    let curves = figure_data(figure)?;
    let png = out_dir.join(format!("{}.png", figure.file_stem()));
    let svg = out_dir.join(format!("{}.svg", figure.file_stem()));
    let draw_error = |path: &Path, e: &dyn std::fmt::Display| ReportError::Draw {
        path: path.to_owned(),
        message: e.to_string(),
    };

    let (width, height) = (1000u32, 700u32);
    let mut rgb = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        draw_curves(&root, figure.title(), &curves).map_err(|e| draw_error(&png, &e))?;
    }
    let mut svg_text = String::new();
    {
        let root = SVGBackend::with_string(&mut svg_text, (width, height)).into_drawing_area();
        draw_curves(&root, figure.title(), &curves).map_err(|e| draw_error(&svg, &e))?;
    }
    let png_bytes = encode_png(&rgb, width, height).map_err(|e| draw_error(&png, &e))?;
    write_atomically(&png, &png_bytes).map_err(|source| ReportError::Write {
        path: png.clone(),
        source,
    })?;
    write_atomically(&svg, svg_text.as_bytes()).map_err(|source| ReportError::Write {
        path: svg.clone(),
        source,
    })?;
    Ok(vec![png, svg])
}

fn draw_curves<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    curves: &[Curve],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    register_fonts();
    root.fill(&WHITE)?;
    let values = || curves.iter().flat_map(|(_, p)| p.iter().map(|&(_, f)| f));
    let max = values().fold(0.0f64, f64::max);
    // Whole decades from the smallest positive value, so no curve is clipped into a false floor.
    let smallest = values().filter(|&f| f > 0.0).fold(max, f64::min);
    let min = 10f64.powf(smallest.log10().floor());
    let top = 10f64.powf(max.log10().ceil());
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FONT, 26))
        .margin(20)
        .x_label_area_size(55)
        .y_label_area_size(90)
        .build_cartesian_2d(-90.0..90.0, (min..top).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("detector zenith θ_r (°), + specular side, − toward the source; θ_i = 60°")
        .y_desc("f00 (sr⁻¹)")
        .label_style((FONT, 18))
        .axis_desc_style((FONT, 20))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    let colors = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
    ];
    for ((label, points), color) in curves.iter().zip(colors) {
        chart
            .draw_series(LineSeries::new(
                points.iter().map(|&(x, y)| (x, y.max(min))),
                color.stroke_width(2),
            ))?
            .label(label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(3))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font((FONT, 20))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    root.present()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lower_q_puts_more_energy_in_the_wings_and_peaks_at_specular() {
        let data = figure_data(PaperFigure::Fig2).unwrap();
        let at = |curve: &[(f64, f64)], zenith: f64| {
            curve
                .iter()
                .find(|&&(x, _)| (x - zenith).abs() < 1e-9)
                .unwrap()
                .1
        };
        let (q15, q25) = (&data[0].1, &data[2].1);
        // Heavier tails (smaller q): lower specular peak, higher far wing.
        assert!(at(q15, 60.0) < at(q25, 60.0));
        assert!(at(q15, -30.0) > at(q25, -30.0));
        // At specular the facet is flat: f00 = P(0) (R_s + R_p)/2 / (4 cos²θ_i), P(0) = (q−1)/(πa).
        let (rs, rp) = crate::optics::fresnel_amplitudes(
            60f64.to_radians().cos(),
            RefractiveIndex::new(1.2, 0.2).permittivity(),
        );
        for ((_, curve), q) in data.iter().zip([1.5, 1.8, 2.5]) {
            let a = 2.0 * 0.1 * 0.1;
            let expect =
                (q - 1.0) / (std::f64::consts::PI * a) * 0.5 * (rs.norm_sqr() + rp.norm_sqr())
                    / (4.0 * 0.25);
            assert!((at(curve, 60.0) / expect - 1.0).abs() < 1e-12, "q={q}");
        }
    }

    #[test]
    fn figures_are_written_as_png_and_svg() {
        let dir = tempfile::tempdir().unwrap();
        let paths = write_paper_figure(PaperFigure::Fig3, dir.path()).unwrap();
        let png = image::open(&paths[0]).unwrap();
        assert_eq!((png.width(), png.height()), (1000, 700));
        let svg = std::fs::read_to_string(&paths[1]).unwrap();
        assert!(svg.contains("detector zenith") && svg.contains("σ = 0.3"));
    }
}
