//! Draws docs/images/car_day_ground.png: over the day of `scenes/car_day.toml`, the environment's
//! ground solved as a surface of its own (docs/design.md §1.8), the asphalt ground part beside
//! the car (its mean and its range: the car's shadow), the cabin's air and the outside air.
//!
//! `cargo run --release --example car_day_ground -- docs/images/car_day_ground.png`

use irpol::progress::Silent;
use irpol::scene::load_scene;
use irpol::thermal_scene::{part_series, solve_scene};
use plotters::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "car_day_ground.png".into());
    let root_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = load_scene(&root_dir.join("scenes/car_day.toml"))?;
    let solution = solve_scene(&scene, &[], &Silent)?;
    let series = part_series(&scene, &solution);
    let find = |name: &str| {
        series
            .iter()
            .find(|s| s.name == name)
            .ok_or_else(|| format!("car_day.toml has no series {name}"))
    };
    let hours: Vec<f64> = solution.times_s.iter().map(|t| t / 3600.0).collect();
    let air: Vec<f64> = solution.weather.iter().map(|w| w.air_k).collect();
    let asphalt = find("car/ground")?;
    let mean = |name: &str| -> Result<Vec<f64>, String> {
        Ok(find(name)?.surface_k.iter().map(|s| s[1]).collect())
    };
    let lines = [
        (
            "environment's ground (solved)",
            mean("environment/ground")?,
            0,
        ),
        ("asphalt part: mean, range shaded", mean("car/ground")?, 1),
        ("cabin air", mean("enclosure/cabin")?, 3),
        ("outside air", air.clone(), 2),
    ];
    let noon = solution.times_s.iter().position(|&t| t == 43200.0);
    if let Some(i) = noon {
        for (label, values, _) in &lines {
            println!("12:00 UTC: {label} {:.2} K", values[i]);
        }
    }

    irpol::plot_style::register_fonts();
    let root = BitMapBackend::new(&out, (900, 540)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "car_day.toml: the environment's ground follows the day",
            (irpol::plot_style::FONT, 20),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d(0.0..24.0, 280.0..335.0)?;
    chart
        .configure_mesh()
        .x_desc("hours from 2026-06-21 00:00 UTC (local summer time = UTC + 2)")
        .y_desc("temperature (K)")
        .label_style((irpol::plot_style::FONT, 14))
        .draw()?;
    let band = Palette99::pick(1).mix(0.2);
    chart.draw_series(std::iter::once(Polygon::new(
        hours
            .iter()
            .zip(&asphalt.surface_k)
            .map(|(&h, s)| (h, s[0]))
            .chain(
                hours
                    .iter()
                    .zip(&asphalt.surface_k)
                    .rev()
                    .map(|(&h, s)| (h, s[2])),
            )
            .collect::<Vec<_>>(),
        band.filled(),
    )))?;
    for (label, values, colour) in lines {
        let colour = Palette99::pick(colour).to_rgba();
        chart
            .draw_series(LineSeries::new(
                hours.iter().copied().zip(values),
                colour.stroke_width(2),
            ))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font((irpol::plot_style::FONT, 14))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    root.present()?;
    println!(
        "wrote {out} (the shaded band: the asphalt part's range, its cool end in the car's shadow)"
    );
    Ok(())
}
