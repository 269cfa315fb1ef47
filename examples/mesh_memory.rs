//! Time and peak memory of a large mesh through the scene's path: read (a binary PLY grid of
//! about N triangles, `mesh_support::GridPly`, held in memory as the loader holds the file's
//! bytes) or generate (a procedural plane), shade, and build the ray-tracing hierarchy
//! (docs/verification.md, Benchmarks). Run under `/usr/bin/time -v` for the peak RSS:
//!
//! ```text
//! cargo run --release --example mesh_memory -- ply 1000000
//! cargo run --release --example mesh_memory -- ply-parser 1000000   # the parser path
//! cargo run --release --example mesh_memory -- plane 5000000
//! ```
//!
//! Every stage's result stays alive to the end (the raw mesh, the shaded one and the
//! hierarchy), so the peak is an upper bound of what a scene of that mesh holds.

#[path = "../tests/it/mesh_support.rs"]
mod mesh_support;

use irpol::scene::mesh::{bounding_diagonal, shade_mesh, ObjectShading, Transform};
use irpol::scene::ply::{parse_ply, parse_ply_through_parser};
use irpol::scene::procedural::plane;
use irpol::transport::accel::Accelerator;
use mesh_support::GridPly;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let triangles = args.get(1).and_then(|n| n.parse::<usize>().ok());
    let (Some(mode), Some(triangles)) = (args.first(), triangles) else {
        eprintln!("usage: mesh_memory ply|ply-parser|plane TRIANGLES");
        return ExitCode::FAILURE;
    };
    let start = Instant::now();
    let raw = match mode.as_str() {
        "ply" | "ply-parser" => {
            let bytes = GridPly::with_triangles(triangles, false).bytes();
            println!("file: {:.1} MB", bytes.len() as f64 / 1e6);
            let start = Instant::now();
            let read = if mode == "ply" {
                parse_ply(&bytes)
            } else {
                parse_ply_through_parser(&bytes)
            };
            println!(
                "read: {:.2} s, peak {}",
                start.elapsed().as_secs_f64(),
                peak_rss()
            );
            read.expect("the grid is a valid PLY")
        }
        "plane" => {
            let cells = ((triangles as f64 / 2.0).sqrt().ceil()) as u32;
            plane([100.0, 100.0], [cells, cells])
        }
        _ => {
            eprintln!("unknown mode '{mode}': ply, ply-parser or plane");
            return ExitCode::FAILURE;
        }
    };
    let setup = ObjectShading {
        transform: Transform::new(1.0, [0.0; 3], [0.0; 3]),
        crease_angle_deg: 30.0,
        part_temperature: &[Some(300.0)],
        part_surface: &[0],
    };
    let shading = Instant::now();
    let (shaded, _) = shade_mesh(&raw, &setup).expect("the grid shades");
    println!(
        "shade: {:.2} s ({} triangles, {} shading vertices), peak {}",
        shading.elapsed().as_secs_f64(),
        shaded.triangles.len(),
        shaded.positions.len(),
        peak_rss()
    );
    let building = Instant::now();
    let accelerator = Accelerator::new(&shaded, bounding_diagonal(&shaded.positions));
    println!(
        "hierarchy: {:.2} s, peak {}, now {}",
        building.elapsed().as_secs_f64(),
        peak_rss(),
        rss("VmRSS:")
    );
    println!("total: {:.2} s", start.elapsed().as_secs_f64());
    drop(accelerator);
    drop(raw);
    ExitCode::SUCCESS
}

/// The process's peak resident memory so far (Linux).
fn peak_rss() -> String {
    rss("VmHWM:")
}

/// A memory line of `/proc/self/status` in MB, or "?" where there is none.
fn rss(key: &str) -> String {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| {
            let line = status.lines().find(|l| l.starts_with(key))?;
            let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(format!("{:.0} MB", kb / 1e3))
        })
        .unwrap_or_else(|| "?".into())
}
