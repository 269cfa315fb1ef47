//! irpol's integration tests, gathered into one test binary: each file here was its own test
//! crate, and each of those linked the whole library (45 links took most of `cargo test`'s
//! build). One crate links once. Run one area with `cargo test --release --test it fit_files`.

// Helpers shared by several test modules.
mod camera_support;
mod common;
mod fit_support;
mod mesh_support;
mod report_support;

mod atmosphere_table;
mod cli;
mod docs_examples;
mod dofp_demosaic;
mod fit_dense_choice;
mod fit_files;
mod fit_quality;
mod fit_shipped;
mod fit_synthetic;
mod fit_undetermined;
mod fuzz_readers;
mod interrupt;
mod measure_csv;
mod measure_layout;
mod mesh_part_temperatures;
mod mitsuba_interop;
mod pbrdf_physics;
mod ply_binary;
mod render_camera;
mod render_car;
mod render_errors;
mod render_outputs;
mod render_physics;
mod render_spectral;
mod render_split;
mod render_tables;
mod render_transport;
mod report_fit;
mod report_index;
mod report_rebuild;
mod report_scale;
mod report_spectral;
mod robustness;
mod scatmech_golden;
mod scene_init_cli;
mod spectral_limits;
mod spectral_materials;
mod sun_cli;
mod thermal_batch;
mod thermal_field;
mod thermal_inputs;
mod thermal_interrupt;
mod thermal_limits;
mod thermal_reuse;
mod thermal_saved;
mod thermal_scene;
mod thermal_solver;
mod thermal_station;
mod thermal_weather;
mod thermal_world;
mod volume_terms;
