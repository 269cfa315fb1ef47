//! Draws docs/images/edge_mtf.png: the MTF measured on rendered slanted edges (ISO 12233,
//! `render::instrument::slanted_edge`) against the closed form of the optics (docs/design.md §1.11),
//! for the cases `tests/it/render_camera.rs` checks.
//!
//! `cargo run --release --example edge_mtf -- docs/images/edge_mtf.png`

#[path = "../tests/it/camera_support.rs"]
mod support;

use irpol::progress::Silent;
use irpol::render::instrument::otf::TransferFunction;
use irpol::render::instrument::slanted_edge::slanted_edge_mtf;
use irpol::render::render;
use irpol::scene::load_scene_text;
use plotters::prelude::*;

const CASES: [(f64, f64, f64, f64); 3] = [
    (1.0, 17.0, 1.0, 0.0),
    (1.0, 12.0, 0.6, 0.5),
    (2.0, 17.0, 0.0, 0.3),
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "edge_mtf.png".into());
    irpol::plot_style::register_fonts();
    let root = BitMapBackend::new(&out, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Slanted-edge MTF of rendered images (points) and the closed form (lines)",
            (irpol::plot_style::FONT, 20),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d(0.0..0.5, 0.0..1.05)?;
    chart
        .configure_mesh()
        .x_desc("frequency along the edge normal (cycles / pixel; Nyquist 0.5)")
        .y_desc("MTF")
        .label_style((irpol::plot_style::FONT, 14))
        .draw()?;
    let frequencies: Vec<f64> = (1..=20).map(|i| 0.025 * i as f64).collect();
    let dir = std::env::temp_dir();
    for (i, (f_number, pitch, fill, sigma)) in CASES.into_iter().enumerate() {
        let optics = format!(
            "[sensor.optics]\nf_number = {f_number}\npixel_pitch_um = {pitch}\n\
             fill_factor = {fill}\nblur_sigma_px = {sigma}\n"
        );
        let scene = load_scene_text(
            &dir.join("edge.toml"),
            &support::slanted_edge_scene(&optics),
        )?;
        let image = render(&scene, &Silent)?.image;
        let s0: Vec<f64> = image.stokes.iter().map(|s| s[0]).collect();
        let edge =
            slanted_edge_mtf(&s0, image.width, 24..136, &frequencies).ok_or("no edge found")?;
        let otf = TransferFunction::new(&scene.sensor, scene.sensor.optics.ok_or("no optics")?);
        let theta = edge.slope.atan();
        let colour = Palette99::pick(i).to_rgba();
        let label = format!("f/{f_number}, {pitch} µm pitch, fill {fill}, σ {sigma} px");
        chart
            .draw_series(LineSeries::new(
                (0..=100).map(|k| {
                    let f = 0.005 * k as f64;
                    (f, otf.at(f * theta.cos(), f * theta.sin()).abs())
                }),
                colour.stroke_width(2),
            ))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart.draw_series(
            frequencies
                .iter()
                .zip(&edge.mtf)
                .map(|(&f, &m)| Circle::new((f, m), 4, colour.filled())),
        )?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font((irpol::plot_style::FONT, 14))
        .position(SeriesLabelPosition::UpperRight)
        .draw()?;
    root.present()?;
    println!("wrote {out}");
    Ok(())
}
