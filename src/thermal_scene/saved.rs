//! A thermal run saved to a file and read back (docs/design.md §2.7): a sweep solves each distinct
//! thermal configuration once and renders every item from the saved solution.
//!
//! **The key.** [`ThermalKey`] addresses a run by content: SHA-256 over everything the solve
//! reads — the resolved `[thermal]` section (site, weather rows, time steps, spin-up, ground,
//! every part's stack and surface properties), the mesh (geometry, parts, starting temperatures),
//! the environment's keys — and over the run's sample instants. The camera, the sensor and the
//! render settings are not in it, so renders from other viewpoints share one run. Every field of
//! the structures hashed is named in [`inputs_digest`] (destructured without `..`): a field added
//! to the scene or the thermal setup stops the build there until it is sorted into the key or out
//! of it, and what is unsure goes in.
//!
//! **Why the instants are in the key.** The solver steps from one sample instant to the next, and
//! an instant asked for is added to the samples (`solve::sample_times`): one that falls between
//! the run's own steps changes the steps around it, and so the temperatures a little everywhere
//! after it (also through the spin-up day). Instants on the run's own sample grid add no sample.
//! The key therefore hashes the sample instants a run recording `t` has: every instant on the
//! grid gets one key (one run serves them all, bit for bit what each one's own run gives), an
//! instant off it a key of its own.
//!
//! **The file.** [`MAGIC`], the format version, the key, the SHA-256 and length of the body, and
//! the body: the whole [`ThermalSolution`] in CBOR (serde, so fields added to it are saved too;
//! CBOR keeps every f64 exactly). A file that is short, damaged, of another format or of another
//! key is refused with an error naming it ([`SavedSolutionError`]).

use super::solve::sample_times;
use super::{solve_scene, ThermalRunError, ThermalSolution};
use crate::progress::Progress;
use crate::scene::thermal::{InstantSettings, ThermalSetup};
use crate::scene::Scene;
use crate::text::{number, path as shown_path};
use crate::thermal::setup::{GroundSurface, SurfaceThermal};
use sha2::{Digest, Sha256};
use std::fmt::{Debug, Write as _};
use std::path::{Path, PathBuf};

/// The first bytes of a saved thermal solution.
pub const MAGIC: &[u8; 16] = b"irpol thermal\n\0\0";

/// The version of the file layout and of the key: a change of either makes old files unreadable
/// (refused, and solved again by a sweep) rather than misread.
pub const FORMAT_VERSION: u32 = 1;

/// Bytes before the body: magic, version, key (hex), body SHA-256, body length.
const HEADER_LEN: usize = MAGIC.len() + 4 + KEY_HEX_LEN + 32 + 8;
const KEY_HEX_LEN: usize = 64;

/// The content address of a thermal run (64 lower-case hex digits of a SHA-256).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ThermalKey(String);

impl ThermalKey {
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Display for ThermalKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// Why a saved thermal solution cannot be written, read or used.
#[derive(Debug, thiserror::Error)]
pub enum SavedSolutionError {
    #[error("{}: cannot read the thermal solution", shown_path(path))]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: cannot write the thermal solution", shown_path(path))]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: not a thermal solution saved by irpol", shown_path(path))]
    NotASolution { path: PathBuf },
    #[error(
        "{}: thermal solution of format {found}, this irpol reads format {FORMAT_VERSION}: solve \
         the run again",
        shown_path(path)
    )]
    Format { path: PathBuf, found: u32 },
    #[error(
        "{}: damaged thermal solution ({detail}): solve the run again",
        shown_path(path)
    )]
    Damaged { path: PathBuf, detail: String },
    /// The file holds the run of other inputs (or of another sample grid) than the scene's.
    #[error(
        "{}: thermal solution {} was solved for other thermal inputs than this scene's{} (key \
         {}): solve this scene's run instead",
        shown_path(path), short(found), at_instant(*time_s), short(expected)
    )]
    KeyMismatch {
        path: PathBuf,
        found: ThermalKey,
        expected: ThermalKey,
        /// The instant asked for; `None` for the run on its own sample grid.
        time_s: Option<f64>,
    },
    #[error("{}: the thermal solution records no t = {} s", shown_path(path), number(*time_s))]
    MissingInstant { path: PathBuf, time_s: f64 },
    /// Instants that one run cannot record bit for bit as their own runs would.
    #[error(
        "t = {} s and t = {} s need separate thermal runs (one of them is off the run's sample \
         grid): solve them apart",
        number(*first_s), number(*other_s)
    )]
    SeparateRuns { first_s: f64, other_s: f64 },
    #[error("no instant to solve the thermal run for: give at least one time")]
    NoInstants,
    #[error(transparent)]
    Run(#[from] ThermalRunError),
}

/// The first 12 hex digits of a key, as messages show it.
fn short(key: &ThermalKey) -> &str {
    &key.0[..12.min(key.0.len())]
}

/// " at t = … s" for an instant, nothing for the run on its own grid.
fn at_instant(time_s: Option<f64>) -> String {
    time_s.map_or(String::new(), |t| format!(" at t = {} s", number(t)))
}

/// Text formatted straight into a SHA-256.
struct Hashing(Sha256);

impl std::fmt::Write for Hashing {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}

impl Hashing {
    /// `name=value;` with the value's full `Debug` form (every f64 to its last bit).
    fn field(&mut self, name: &str, value: &dyn Debug) {
        let _ = write!(self, "{name}={value:?};");
    }
}

/// The keys of a thermal scene's runs, one per instant (s from `start_utc`); equal keys share a
/// run. Refused for a scene without `[thermal]` or an instant outside the run.
pub fn thermal_keys(scene: &Scene, times_s: &[f64]) -> Result<Vec<ThermalKey>, ThermalRunError> {
    let setup = thermal_setup(scene)?;
    if let Some(&t) = times_s
        .iter()
        .find(|&&t| !(t.is_finite() && (0.0..=setup.duration_s).contains(&t)))
    {
        return Err(ThermalRunError::OutsideRun {
            time_s: t,
            duration_s: setup.duration_s,
        });
    }
    let inputs = inputs_digest(scene, setup);
    Ok(times_s
        .iter()
        .map(|&t| key_of(&inputs, setup, &[t]))
        .collect())
}

/// The key of the one run that records every one of `times_s`; none given, the run on its own
/// sample grid (`irpol thermal`'s, which every instant on that grid shares). Refused when the
/// instants need separate runs.
pub fn run_key(scene: &Scene, times_s: &[f64]) -> Result<ThermalKey, SavedSolutionError> {
    if times_s.is_empty() {
        let setup = thermal_setup(scene)?;
        return Ok(key_of(&inputs_digest(scene, setup), setup, &[]));
    }
    let keys = thermal_keys(scene, times_s)?;
    match keys.iter().position(|k| k != &keys[0]) {
        Some(i) => Err(SavedSolutionError::SeparateRuns {
            first_s: times_s[0],
            other_s: times_s[i],
        }),
        None => Ok(keys[0].clone()),
    }
}

fn thermal_setup(scene: &Scene) -> Result<&ThermalSetup, ThermalRunError> {
    scene
        .thermal
        .as_deref()
        .ok_or_else(|| ThermalRunError::NotThermal(shown_path(&scene.path)))
}

/// The key of the run whose samples are the grid's and `extra`'s.
fn key_of(inputs: &Sha256, setup: &ThermalSetup, extra: &[f64]) -> ThermalKey {
    let mut digest = inputs.clone();
    digest.update(b"samples=");
    for s in sample_times(setup, extra).0 {
        digest.update(s.to_bits().to_le_bytes());
    }
    ThermalKey(hex(&digest.finalize()))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().fold(String::new(), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

/// The hash of the scene's thermal inputs (see the module docs for what is in and why).
fn inputs_digest(scene: &Scene, setup: &ThermalSetup) -> Sha256 {
    let Scene {
        // The render's: the camera, the sensor, the render settings, the air between the camera
        // and the scene. (The sensor's band resolves the environment's radiances and the
        // materials' tables for the render; the run reads neither.)
        camera: _,
        sensor: _,
        shading: _,
        aop_mask_dolp: _,
        preview: _,
        transport: _,
        atmosphere: _,
        // The run's environment is its keys, in `thermal_rebuild` below.
        environment: _,
        // The run reads the materials as each part's emissivity, in `setup.surfaces`.
        materials: _,
        // A thermal scene's sun is the weather's, in `setup.weather`.
        sun: _,
        // The scene's name and its messages; no instant in a loaded scene.
        path: _,
        warnings: _,
        thermal_instant: _,
        // The terrains' grids: their heights are vertices of `mesh`, hashed below.
        heightfields: _,
        // `setup`, hashed by `hash_setup`.
        thermal: _,
        air_temperature_k,
        object_names,
        surfaces,
        mesh,
        thermal_rebuild,
    } = scene;
    let mut h = Hashing(Sha256::new());
    h.field("irpol", &env!("CARGO_PKG_VERSION"));
    h.field("format", &FORMAT_VERSION);
    h.field("air_temperature_k", air_temperature_k);
    h.field("object_names", object_names);
    h.field("surfaces", surfaces);
    h.field("mesh", mesh);
    if let Some(InstantSettings {
        environment,
        atmosphere_temperature_given: _, // the render's sky at an instant
        netd_reference_given: _,         // the render's sensor
        sun_irradiance_w_m2: _,          // the render's sun (the run's is the weather's)
    }) = thermal_rebuild
    {
        h.field("environment", environment);
    }
    hash_setup(&mut h, setup);
    h.0
}

/// Every key of the resolved `[thermal]` section.
fn hash_setup(h: &mut Hashing, setup: &ThermalSetup) {
    let ThermalSetup {
        site,
        weather,
        duration_s,
        output_step_s,
        time_step_s,
        shadow_step_s,
        spinup_days,
        ground_temperature_k,
        surfaces,
        ground,
        enclosures,
    } = setup;
    h.field("site", site);
    h.field("weather", weather);
    h.field("duration_s", duration_s);
    h.field("output_step_s", output_step_s);
    h.field("time_step_s", time_step_s);
    h.field("shadow_step_s", shadow_step_s);
    h.field("spinup_days", spinup_days);
    h.field("ground_temperature_k", ground_temperature_k);
    for (i, surface) in surfaces.iter().enumerate() {
        h.field("surface", &i);
        match surface {
            None => h.field("typed", &()),
            Some(surface) => hash_surface(h, surface),
        }
    }
    if let Some(GroundSurface {
        surface,
        initial_k,
        occluded_k,
    }) = ground
    {
        h.field("ground", &"thermal");
        hash_surface(h, surface);
        h.field("ground_initial_k", initial_k);
        h.field("ground_occluded_k", occluded_k);
    }
    h.field("enclosures", enclosures);
}

/// One surface's thermal model, every field.
fn hash_surface(h: &mut Hashing, surface: &SurfaceThermal) {
    let SurfaceThermal {
        stack,
        back,
        solar_absorptance,
        emissivity,
        convection_w_m2k,
        internal_heat,
        enclosure,
        solar_transmittance,
    } = surface;
    h.field("stack", stack);
    h.field("back", back);
    h.field("solar_absorptance", solar_absorptance);
    h.field("emissivity", emissivity);
    h.field("convection_w_m2k", convection_w_m2k);
    h.field("internal_heat", internal_heat);
    h.field("enclosure", enclosure);
    h.field("solar_transmittance", solar_transmittance);
}

/// The file's bytes: header, then the CBOR body.
fn encode(key: &ThermalKey, solution: &ThermalSolution) -> Result<Vec<u8>, std::io::Error> {
    let mut body = Vec::new();
    ciborium::into_writer(solution, &mut body).map_err(std::io::Error::other)?;
    let mut bytes = Vec::with_capacity(HEADER_LEN + body.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(key.0.as_bytes());
    bytes.extend_from_slice(&Sha256::digest(&body));
    bytes.extend_from_slice(&(body.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&body);
    Ok(bytes)
}

/// Saves `solution`, the run of `key`, to `path` atomically (a reader sees the old file or the
/// new one, whole).
pub fn save_solution(
    path: &Path,
    key: &ThermalKey,
    solution: &ThermalSolution,
) -> Result<(), SavedSolutionError> {
    let write_error = |source| SavedSolutionError::Write {
        path: path.to_owned(),
        source,
    };
    let bytes = encode(key, solution).map_err(write_error)?;
    crate::atomic::write_atomically(path, &bytes).map_err(write_error)
}

/// The key a saved solution was made for, and the solution; refused as the module docs say.
pub fn read_solution(path: &Path) -> Result<(ThermalKey, ThermalSolution), SavedSolutionError> {
    let bytes = std::fs::read(path).map_err(|source| SavedSolutionError::Read {
        path: path.to_owned(),
        source,
    })?;
    let damaged = |detail: &str| SavedSolutionError::Damaged {
        path: path.to_owned(),
        detail: detail.to_owned(),
    };
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(SavedSolutionError::NotASolution {
            path: path.to_owned(),
        });
    }
    if bytes.len() < HEADER_LEN {
        return Err(damaged("cut short"));
    }
    let (header, body) = bytes.split_at(HEADER_LEN);
    let field = |start: usize, len: usize| &header[MAGIC.len() + start..MAGIC.len() + start + len];
    let version = u32::from_le_bytes(field(0, 4).try_into().expect("4 bytes"));
    if version != FORMAT_VERSION {
        return Err(SavedSolutionError::Format {
            path: path.to_owned(),
            found: version,
        });
    }
    let key = std::str::from_utf8(field(4, KEY_HEX_LEN))
        .ok()
        .filter(|k| k.bytes().all(|b| b.is_ascii_hexdigit()))
        .ok_or_else(|| damaged("its key is not hex"))?;
    let length = u64::from_le_bytes(field(4 + KEY_HEX_LEN + 32, 8).try_into().expect("8 bytes"));
    if length != body.len() as u64 {
        return Err(damaged("its length does not match"));
    }
    if Sha256::digest(body).as_slice() != field(4 + KEY_HEX_LEN, 32) {
        return Err(damaged("its checksum does not match"));
    }
    let solution: ThermalSolution =
        ciborium::from_reader(body).map_err(|e| damaged(&format!("cannot decode: {e}")))?;
    let rows = solution.times_s.len();
    if solution.surface_k.len() != rows || solution.weather.len() != rows {
        return Err(damaged("its tables differ in length"));
    }
    Ok((ThermalKey(key.to_owned()), solution))
}

/// The solution saved at `path` for rendering `scene` at `time_s`: refused unless it is the run
/// of the scene's key at that instant, records it, and holds a temperature for every vertex.
pub fn solution_for(
    path: &Path,
    scene: &Scene,
    time_s: f64,
) -> Result<ThermalSolution, SavedSolutionError> {
    solution_recording(path, scene, &[time_s])
}

/// The solution saved at `path` of the one run of `scene` recording every one of `times_s`
/// (none: the run on its own grid, [`run_key`]), refused as [`solution_for`] says.
pub fn solution_recording(
    path: &Path,
    scene: &Scene,
    times_s: &[f64],
) -> Result<ThermalSolution, SavedSolutionError> {
    let expected = run_key(scene, times_s)?;
    let (found, solution) = read_solution(path)?;
    if found != expected {
        return Err(SavedSolutionError::KeyMismatch {
            path: path.to_owned(),
            found,
            expected,
            time_s: (times_s.len() == 1).then(|| times_s[0]),
        });
    }
    let vertices = scene.mesh.positions.len();
    if solution.surface_k.iter().any(|row| row.len() != vertices) {
        return Err(SavedSolutionError::Damaged {
            path: path.to_owned(),
            detail: format!("its rows do not hold the scene's {vertices} vertices"),
        });
    }
    let recorded = |t: f64| solution.times_s.iter().any(|&s| (s - t).abs() < 1e-6);
    if let Some(&time_s) = times_s.iter().find(|&&t| !recorded(t)) {
        return Err(SavedSolutionError::MissingInstant {
            path: path.to_owned(),
            time_s,
        });
    }
    Ok(solution)
}

/// Whether a run was read from its file or solved.
#[derive(Debug)]
pub enum RunOrigin {
    /// Read from the file, solved earlier.
    Reused,
    /// Solved and saved to the file; `ignored` says why a file that was there could not be used
    /// (damaged, another format; `None` when there was none, or it lacked an instant asked for,
    /// which the new run adds).
    Solved { ignored: Option<SavedSolutionError> },
}

/// The run of `scene` recording `times_s` (none: the run on its own grid): read from `path` when
/// that holds it with every instant ([`solution_recording`]), else solved and saved to `path`
/// (atomically). Refused when the instants need separate runs.
pub fn load_or_solve(
    scene: &Scene,
    times_s: &[f64],
    path: &Path,
    progress: &dyn Progress,
) -> Result<(ThermalKey, ThermalSolution, RunOrigin), SavedSolutionError> {
    let key = run_key(scene, times_s)?;
    let ignored = match solution_recording(path, scene, times_s) {
        Ok(solution) => return Ok((key, solution, RunOrigin::Reused)),
        Err(SavedSolutionError::Read { source, .. })
            if source.kind() == std::io::ErrorKind::NotFound =>
        {
            None
        }
        Err(SavedSolutionError::MissingInstant { .. }) => None,
        Err(SavedSolutionError::Run(error)) => return Err(error.into()),
        Err(other) => Some(other),
    };
    let solution = solve_scene(scene, times_s, progress)?;
    save_solution(path, &key, &solution)?;
    Ok((key, solution, RunOrigin::Solved { ignored }))
}

/// Solves the scene's run recording `times_s` (which must share one key) and saves it to `path`,
/// unless `path` already holds that run with every one of them (a sweep run again, or the same
/// configuration asked for twice). Returns the key.
pub fn solve_and_save(
    scene: &Scene,
    times_s: &[f64],
    path: &Path,
    progress: &dyn Progress,
) -> Result<ThermalKey, SavedSolutionError> {
    if times_s.is_empty() {
        return Err(SavedSolutionError::NoInstants);
    }
    load_or_solve(scene, times_s, path, progress).map(|(key, _, _)| key)
}
