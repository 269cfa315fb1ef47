//! Outputs of `irpol thermal` (docs/design.md §2.6): the per-part temperature table, per-vertex PLY meshes
//! at each recorded instant, the temperature plot and a JSON summary, swapped into the output
//! folder as one set (see [`StagedFolder`]).

use super::thermal_plot::temperature_plot_png;
use crate::atomic::StagedFolder;
use crate::scene::Scene;
use crate::thermal_scene::{part_series, PartSeries, SolveStats, ThermalSolution};
use std::collections::BTreeSet;
use std::io;
use std::path::Path;

/// `temperatures.csv`: `time_s,part,t_surface_min_k,t_surface_mean_k,t_surface_max_k`, written
/// by the csv crate, so a part named `ball, left` or `say "hi"` is one quoted field (RFC 4180).
pub fn temperatures_csv(times_s: &[f64], parts: &[PartSeries]) -> String {
    let mut csv = csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(Vec::new());
    let header = [
        "time_s",
        "part",
        "t_surface_min_k",
        "t_surface_mean_k",
        "t_surface_max_k",
    ];
    // Writing into memory cannot fail.
    let _ = csv.write_record(header);
    for (i, t) in times_s.iter().enumerate() {
        for part in parts {
            let [lo, mean, hi] = part.surface_k[i];
            let _ = csv.write_record([
                t.to_string(),
                part.name.clone(),
                format!("{lo:.4}"),
                format!("{mean:.4}"),
                format!("{hi:.4}"),
            ]);
        }
    }
    let bytes = csv.into_inner().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}

/// The name of the PLY of recorded instant `index` at `time_s`.
pub fn surface_ply_name(index: usize, time_s: f64) -> String {
    format!("surface_{index:04}_{}s.ply", time_s.round())
}

/// The scene's shading mesh with `temperature` per vertex (binary little-endian PLY; the same
/// `temperature` property irpol reads, so a step can be rendered or viewed directly).
///
/// Written by hand rather than through ply-rs-bw's writer, which takes a map of named properties
/// per element: for a terrain of 2.56 M vertices and 5.1 M faces that was ~4 GB and seconds per
/// file, for a format that is a header and fixed-size records.
pub fn surface_ply(scene: &Scene, temperatures_k: &[f64], time_s: f64) -> io::Result<Vec<u8>> {
    let mesh = &scene.mesh;
    let comment = format!(
        "irpol thermal: surface temperatures (K) of {} at time_s = {time_s}",
        scene.path.display()
    )
    .replace(['\n', '\r'], " ");
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment {comment}\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nproperty float temperature\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    );
    let mut bytes =
        Vec::with_capacity(header.len() + 16 * mesh.positions.len() + 13 * mesh.triangles.len());
    bytes.extend_from_slice(header.as_bytes());
    for (p, &t) in mesh.positions.iter().zip(temperatures_k) {
        for v in [p.x, p.y, p.z, t] {
            bytes.extend_from_slice(&(v as f32).to_le_bytes());
        }
    }
    for triangle in &mesh.triangles {
        bytes.push(3);
        for &v in triangle {
            let index = i32::try_from(v).map_err(io::Error::other)?;
            bytes.extend_from_slice(&index.to_le_bytes());
        }
    }
    Ok(bytes)
}

/// `summary.json` of a thermal run.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct ThermalSummary {
    pub scene: String,
    pub start_utc: String,
    pub duration_s: f64,
    pub recorded_instants: usize,
    #[serde(skip_deserializing)]
    pub stats: SolveStats,
    pub seconds: f64,
    /// Probable mistakes noticed while loading the scene.
    #[serde(default)]
    pub warnings: Vec<String>,
    pub files: Vec<String>,
}

/// Writes every output of a thermal run into `out_dir` as one set.
pub fn write_thermal_outputs(
    scene: &Scene,
    solution: &ThermalSolution,
    out_dir: &Path,
    seconds: f64,
) -> io::Result<ThermalSummary> {
    let setup = scene.thermal.as_deref().ok_or_else(|| {
        io::Error::other(format!(
            "{} has no [thermal] section",
            crate::text::path(&scene.path)
        ))
    })?;
    let parts = part_series(scene, solution);
    let staged = StagedFolder::begin(out_dir)?;
    let mut files = Vec::new();
    let mut put = |name: String, bytes: &[u8]| -> io::Result<()> {
        staged.write(&name, bytes)?;
        files.push(name);
        Ok(())
    };
    put(
        "temperatures.csv".into(),
        temperatures_csv(&solution.times_s, &parts).as_bytes(),
    )?;
    put(
        "temperatures.png".into(),
        &temperature_plot_png(scene, solution, &parts)?,
    )?;
    for (i, (t, row)) in solution.times_s.iter().zip(&solution.surface_k).enumerate() {
        put(surface_ply_name(i, *t), &surface_ply(scene, row, *t)?)?;
    }
    files.push("summary.json".into());
    let summary = ThermalSummary {
        scene: scene.path.display().to_string(),
        start_utc: crate::emitter::format_time_utc(&setup.site.start_utc),
        duration_s: setup.duration_s,
        recorded_instants: solution.times_s.len(),
        stats: solution.stats,
        seconds,
        warnings: scene.warnings.clone(),
        files,
    };
    let json = serde_json::to_string_pretty(&summary).map_err(io::Error::other)?;
    staged.write("summary.json", json.as_bytes())?;
    let earlier = earlier_outputs(out_dir);
    staged.commit(&|name| earlier.contains(name) || is_surface_ply(name))?;
    Ok(summary)
}

/// Names listed by the summary of an earlier run into `out_dir`.
fn earlier_outputs(out_dir: &Path) -> BTreeSet<String> {
    std::fs::read_to_string(out_dir.join("summary.json"))
        .ok()
        .and_then(|text| serde_json::from_str::<ThermalSummary>(&text).ok())
        .map(|s| s.files.into_iter().collect())
        .unwrap_or_default()
}

fn is_surface_ply(name: &str) -> bool {
    name.starts_with("surface_") && name.ends_with("s.ply")
}

#[cfg(test)]
mod csv_tests {
    use super::*;

    /// A part name with a comma or a quote is one quoted field: every row has the header's five
    /// fields (issue 42: `ball, left` made six).
    #[test]
    fn part_names_are_quoted_as_csv_fields() {
        let parts = [
            PartSeries {
                name: "ball, left".into(),
                surface_k: vec![[290.0, 291.0, 292.0]],
            },
            PartSeries {
                name: "say \"hi\"".into(),
                surface_k: vec![[1.0, 2.0, 3.0]],
            },
        ];
        let text = temperatures_csv(&[0.0], &parts);
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
        assert_eq!(rows.len(), 2);
        assert!(rows.iter().all(|r| r.len() == 5), "{text}");
        assert_eq!(&rows[0][1], "ball, left");
        assert_eq!(&rows[1][1], "say \"hi\"");
        assert!(text.starts_with("time_s,part,t_surface_min_k,"), "{text}");
        assert!(
            text.contains("\n0,\"ball, left\",290.0000,291.0000,292.0000\n"),
            "{text}"
        );
    }
}
