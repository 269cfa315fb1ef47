//! A procedural sedan on a ground plane for the LWIR demo scene (`scenes/car.obj`): body panels
//! at many orientations, a hood, roof and trunk, a sloped windshield and rear window, side windows,
//! pillars, mirrors, bumpers, grille, headlights, tyres and wheels, and the ground, each an OBJ
//! group so that the scene can give it a material and a temperature.
//!
//! World frame: z up, the car's nose toward +x, its left side toward +y, the ground at z = 0.
//! Units are metres. Neighbouring panels share vertices, so part temperatures blend across seams.

use super::mesh::{FaceOrigin, RawFace, RawMesh};
use super::obj::format_obj;
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::path::Path;

const HALF_LENGTH: f64 = 2.30;
const HALF_WIDTH: f64 = 0.90;
/// Plan-view corner radius of the nose and tail.
const CORNER_RADIUS: f64 = 0.30;
const GROUND_CLEARANCE: f64 = 0.20;
const WHEEL_X: f64 = 1.38;
const WHEEL_Y: f64 = 0.73;
const WHEEL_RADIUS: f64 = 0.32;
const ARCH_RADIUS: f64 = 0.40;
/// Hood starts and trunk ends where the greenhouse meets the deck.
const COWL_X: f64 = 1.30;
const TRUNK_X: f64 = -1.30;

/// Mesh builder that orients every face away from an interior point of its component.
struct Builder {
    mesh: RawMesh,
}

impl Builder {
    fn vertex(&mut self, p: Vector3<f64>) -> u32 {
        self.mesh.positions.push(p);
        (self.mesh.positions.len() - 1) as u32
    }

    fn triangle(&mut self, mut v: [u32; 3], inside: Vector3<f64>, part: &str) {
        let [a, b, c] = v.map(|i| self.mesh.positions[i as usize]);
        let normal = (b - a).cross(&(c - a));
        if normal.dot(&((a + b + c) / 3.0 - inside)) < 0.0 {
            v.swap(1, 2);
        }
        let part = self.mesh.part_index(part);
        let origin = FaceOrigin::Index(self.mesh.faces.len() + 1);
        self.mesh.faces.push(RawFace {
            vertices: v,
            normals: None,
            part,
            origin,
        });
    }

    fn quad(&mut self, [a, b, c, d]: [u32; 4], inside: Vector3<f64>, part: &str) {
        self.triangle([a, b, c], inside, part);
        self.triangle([a, c, d], inside, part);
    }

    /// An axis-aligned box, all six faces.
    fn cuboid(&mut self, lo: Vector3<f64>, hi: Vector3<f64>, part: &str) {
        let corner = |i: u32| {
            Vector3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let v: Vec<u32> = (0..8).map(|i| self.vertex(corner(i))).collect();
        let centre = (lo + hi) / 2.0;
        for face in [
            [0, 1, 3, 2],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 3, 7, 5],
        ] {
            self.quad(face.map(|i| v[i]), centre, part);
        }
    }
}

/// Piecewise-linear profile through (x, value) knots sorted by x.
fn profile(knots: &[(f64, f64)], x: f64) -> f64 {
    let i = knots
        .partition_point(|k| k.0 <= x)
        .clamp(1, knots.len() - 1);
    let ((x0, y0), (x1, y1)) = (knots[i - 1], knots[i]);
    y0 + (y1 - y0) * ((x - x0) / (x1 - x0)).clamp(0.0, 1.0)
}

/// Height of the deck (trunk lid, cabin belt, cowl, hood) along the car.
fn deck_height(x: f64) -> f64 {
    profile(
        &[
            (-2.30, 0.80),
            (-2.22, 0.93),
            (-2.05, 0.985),
            (TRUNK_X, 1.00),
            (COWL_X, 0.99),
            (2.05, 0.84),
            (2.22, 0.78),
            (2.30, 0.70),
        ],
        x,
    )
}

/// Half width in plan view, with rounded nose and tail corners.
fn half_width(x: f64) -> f64 {
    let straight = HALF_LENGTH - CORNER_RADIUS;
    let beyond = x.abs() - straight;
    if beyond <= 0.0 {
        HALF_WIDTH
    } else {
        HALF_WIDTH - CORNER_RADIUS
            + (CORNER_RADIUS * CORNER_RADIUS - beyond * beyond)
                .max(0.0)
                .sqrt()
    }
}

/// Bottom edge of the body: the ground clearance, raised into arches over the wheels.
fn bottom_height(x: f64) -> f64 {
    let arch = |centre: f64| {
        let d = x - centre;
        if d.abs() < ARCH_RADIUS {
            WHEEL_RADIUS + (ARCH_RADIUS * ARCH_RADIUS - d * d).sqrt()
        } else {
            0.0
        }
    };
    GROUND_CLEARANCE.max(arch(WHEEL_X)).max(arch(-WHEEL_X))
}

/// Lower body: cross-sections lofted from tail to nose, closed underneath and capped by the
/// bumpers. Each section runs up the left side, over the deck and down the right side.
fn lower_body(b: &mut Builder) {
    const STATIONS: usize = 93;
    const DECK_SEGMENTS: usize = 12;
    // Left side from the rocker to the shoulder: (fraction of half width, fraction of height).
    const SIDE: [(f64, f64); 6] = [
        (0.93, 0.0),
        (0.985, 0.12),
        (1.0, 0.40),
        (0.99, 0.65),
        (0.96, 0.85),
        (0.90, 0.985),
    ];
    let deck_edge = 0.84;
    let mut rings: Vec<Vec<u32>> = Vec::with_capacity(STATIONS);
    let mut centres = Vec::with_capacity(STATIONS);
    let mut xs = Vec::with_capacity(STATIONS);
    for i in 0..STATIONS {
        let x = -HALF_LENGTH + 2.0 * HALF_LENGTH * i as f64 / (STATIONS - 1) as f64;
        let (w, bottom, deck) = (half_width(x), bottom_height(x), deck_height(x));
        let height = deck - bottom;
        let mut ring = Vec::new();
        for &(fy, fz) in &SIDE {
            ring.push(b.vertex(Vector3::new(x, fy * w, bottom + fz * height)));
        }
        for j in 0..=DECK_SEGMENTS {
            let u = 1.0 - 2.0 * j as f64 / DECK_SEGMENTS as f64;
            let crown = 0.03 * (1.0 - u * u);
            ring.push(b.vertex(Vector3::new(x, deck_edge * w * u, deck + crown)));
        }
        for &(fy, fz) in SIDE.iter().rev() {
            ring.push(b.vertex(Vector3::new(x, -fy * w, bottom + fz * height)));
        }
        rings.push(ring);
        centres.push(Vector3::new(x, 0.0, 0.5 * (bottom + deck)));
        xs.push(x);
    }
    let n = rings[0].len();
    let deck_range = SIDE.len()..SIDE.len() + DECK_SEGMENTS;
    for i in 0..STATIONS - 1 {
        let inside = (centres[i] + centres[i + 1]) / 2.0;
        let x_mid = 0.5 * (xs[i] + xs[i + 1]);
        for k in 0..n {
            // k = n − 1 closes the loop underneath (right rocker back to the left one).
            let k1 = (k + 1) % n;
            let part = if deck_range.contains(&k) {
                if x_mid > COWL_X {
                    "hood"
                } else if x_mid < TRUNK_X {
                    "trunk"
                } else {
                    "body"
                }
            } else {
                "body"
            };
            let quad = [rings[i][k], rings[i][k1], rings[i + 1][k1], rings[i + 1][k]];
            b.quad(quad, inside, part);
        }
    }
    // Bumper caps: fans from the section centroid; inside is just behind the cap.
    for (i, inward) in [(0usize, 0.1), (STATIONS - 1, -0.1)] {
        let ring = &rings[i];
        let centroid = ring
            .iter()
            .map(|&v| b.mesh.positions[v as usize])
            .sum::<Vector3<f64>>()
            / n as f64;
        let centre = b.vertex(centroid);
        let inside = centroid + Vector3::new(inward, 0.0, 0.0);
        for k in 0..n {
            b.triangle([centre, ring[k], ring[(k + 1) % n]], inside, "bumpers");
        }
    }
}

/// Segments of the cabin across the car on its front and rear edges.
const ACROSS: usize = 8;
/// Segments of the cabin along each side.
const ALONG: usize = 16;
/// Bands of the cabin from belt to roof.
const RINGS: usize = 6;

/// Cabin: rings from the belt rectangle up to the roof rectangle (front edge = windshield, rear
/// edge = rear window, sides = side windows between pillars), then the crowned roof.
fn greenhouse(b: &mut Builder) {
    let loop_uv = cabin_loop();
    let point = |k: usize, (u, t): (f64, f64)| {
        let (rear, front, w, z) = ring_geometry(k);
        Vector3::new(front + t * (rear - front), u * w, z)
    };
    let rings: Vec<Vec<u32>> = (0..=RINGS)
        .map(|k| loop_uv.iter().map(|&uv| b.vertex(point(k, uv))).collect())
        .collect();
    let n = loop_uv.len();
    for k in 0..RINGS {
        let (rear, front, _, z0) = ring_geometry(k);
        let (_, _, _, z1) = ring_geometry(k + 1);
        let inside = Vector3::new(0.5 * (rear + front), 0.0, 0.5 * (z0 + z1));
        for m in 0..n {
            let m1 = (m + 1) % n;
            let quad = [rings[k][m], rings[k][m1], rings[k + 1][m1], rings[k + 1][m]];
            b.quad(quad, inside, cabin_part(k, m));
        }
    }
    roof(b, &rings[RINGS], n);
}

/// Boundary loop of an ACROSS × ALONG grid: front edge (left → right), right side (front →
/// rear), rear edge (right → left), left side (rear → front); entries are (u, t) with u across
/// (+1 left) and t along (0 front, 1 rear).
fn cabin_loop() -> Vec<(f64, f64)> {
    let mut loop_uv: Vec<(f64, f64)> = Vec::new();
    for j in 0..ACROSS {
        loop_uv.push((1.0 - 2.0 * j as f64 / ACROSS as f64, 0.0));
    }
    for j in 0..ALONG {
        loop_uv.push((-1.0, j as f64 / ALONG as f64));
    }
    for j in 0..ACROSS {
        loop_uv.push((-1.0 + 2.0 * j as f64 / ACROSS as f64, 1.0));
    }
    for j in 0..ALONG {
        loop_uv.push((1.0, 1.0 - j as f64 / ALONG as f64));
    }
    loop_uv
}

/// Ring `k` of the cabin (0 = belt, RINGS = roof edge): its rear and front x, half width and
/// height, bulging outward between belt and roof.
fn ring_geometry(k: usize) -> (f64, f64, f64, f64) {
    let (belt_rear, belt_front, belt_w, belt_z) = (-1.22, 1.22, 0.74, 0.99);
    let (roof_rear, roof_front, roof_w, roof_z) = (-0.55, 0.45, 0.62, 1.44);
    let s = k as f64 / RINGS as f64;
    let bulge = (PI * s).sin();
    let rear = belt_rear + s * (roof_rear - belt_rear) - 0.03 * bulge;
    let front = belt_front + s * (roof_front - belt_front) + 0.03 * bulge;
    let w = belt_w + s * (roof_w - belt_w) + 0.04 * bulge;
    let z = belt_z + s * (roof_z - belt_z);
    (rear, front, w, z)
}

/// The part of the cabin quad of band `k` starting at loop entry `m`: glass between pillars,
/// frame on the first and last bands of the sides.
fn cabin_part(k: usize, m: usize) -> &'static str {
    let frame_band = k == 0 || k == RINGS - 1;
    if m < ACROSS {
        if m == 0 || m == ACROSS - 1 {
            "pillars"
        } else {
            "windshield"
        }
    } else if (ACROSS + ALONG..2 * ACROSS + ALONG).contains(&m) {
        let j = m - ACROSS - ALONG;
        if j == 0 || j == ACROSS - 1 {
            "pillars"
        } else {
            "rear_window"
        }
    } else {
        // Along a side, j counts from the front (right side) or from the rear (left).
        let j = if m < ACROSS + ALONG {
            m - ACROSS
        } else {
            ALONG - 1 - (m - 2 * ACROSS - ALONG)
        };
        let pillar = j == 0 || j == ALONG / 2 || j == ALONG - 1;
        if pillar || frame_band {
            "pillars"
        } else {
            "side_windows"
        }
    }
}

/// Roof grid sharing its boundary with the top ring `top` (`n` loop entries), crowned upward.
fn roof(b: &mut Builder, top: &[u32], n: usize) {
    let boundary_index = |a: usize, c: usize| -> Option<usize> {
        // Grid point (a across from the left, c along from the front) on the loop, if any.
        if c == 0 {
            Some(a)
        } else if a == ACROSS {
            Some(ACROSS + c)
        } else if c == ALONG {
            Some(ACROSS + ALONG + (ACROSS - a))
        } else if a == 0 {
            Some(2 * ACROSS + ALONG + (ALONG - c))
        } else {
            None
        }
        .map(|m| m % n)
    };
    let (rear, front, w, z) = ring_geometry(RINGS);
    let mut grid = vec![vec![0u32; ALONG + 1]; ACROSS + 1];
    for (a, column) in grid.iter_mut().enumerate() {
        for (c, slot) in column.iter_mut().enumerate() {
            *slot = match boundary_index(a, c) {
                Some(m) => top[m],
                None => {
                    let u = 1.0 - 2.0 * a as f64 / ACROSS as f64;
                    let t = c as f64 / ALONG as f64;
                    let v = 2.0 * t - 1.0;
                    let crown = 0.05 * (1.0 - u * u) * (1.0 - v * v);
                    b.vertex(Vector3::new(front + t * (rear - front), u * w, z + crown))
                }
            };
        }
    }
    let inside = Vector3::new(0.5 * (rear + front), 0.0, 1.2);
    for a in 0..ACROSS {
        for c in 0..ALONG {
            let quad = [
                grid[a][c],
                grid[a + 1][c],
                grid[a + 1][c + 1],
                grid[a][c + 1],
            ];
            b.quad(quad, inside, "roof");
        }
    }
}

/// A tyre revolved about the axle (y), with a dished wheel on the outer side and a flat one
/// inside. `side` is +1 for the left wheels, −1 for the right.
fn wheel(b: &mut Builder, x: f64, side: f64) {
    const SEGMENTS: usize = 40;
    let centre = Vector3::new(x, side * WHEEL_Y, WHEEL_RADIUS);
    // (radius, offset toward the outside) from the inner sidewall over the tread to the outer one.
    let tyre: [(f64, f64); 8] = [
        (0.19, -0.11),
        (0.29, -0.11),
        (0.315, -0.095),
        (0.32, -0.07),
        (0.32, 0.07),
        (0.315, 0.095),
        (0.29, 0.11),
        (0.19, 0.11),
    ];
    let rim: [(f64, f64); 3] = [(0.19, 0.11), (0.13, 0.09), (0.05, 0.095)];
    let at = |r: f64, offset: f64, j: usize| {
        let angle = 2.0 * PI * j as f64 / SEGMENTS as f64;
        centre + Vector3::new(r * angle.cos(), side * offset, r * angle.sin())
    };
    let revolve = |b: &mut Builder, profile: &[(f64, f64)]| -> Vec<Vec<u32>> {
        profile
            .iter()
            .map(|&(r, o)| (0..SEGMENTS).map(|j| b.vertex(at(r, o, j))).collect())
            .collect()
    };
    let bands = |b: &mut Builder, rings: &[Vec<u32>], inside: Vector3<f64>, part: &str| {
        for pair in rings.windows(2) {
            for j in 0..SEGMENTS {
                let j1 = (j + 1) % SEGMENTS;
                b.quad(
                    [pair[0][j], pair[0][j1], pair[1][j1], pair[1][j]],
                    inside,
                    part,
                );
            }
        }
    };
    let tyre_rings = revolve(b, &tyre);
    bands(b, &tyre_rings, centre, "tyres");
    // The outer wheel starts on the tyre's last ring so the two share their seam.
    let mut rim_rings = vec![tyre_rings[tyre.len() - 1].clone()];
    rim_rings.extend(revolve(b, &rim[1..]));
    let outward = Vector3::new(0.0, side * 0.5, 0.0);
    bands(b, &rim_rings, centre - outward, "wheels");
    let hub = b.vertex(centre + Vector3::new(0.0, side * 0.10, 0.0));
    let last = rim_rings.last().cloned().unwrap_or_default();
    for j in 0..SEGMENTS {
        b.triangle(
            [hub, last[j], last[(j + 1) % SEGMENTS]],
            centre - outward,
            "wheels",
        );
    }
    let inner_hub = b.vertex(centre - Vector3::new(0.0, side * 0.10, 0.0));
    let first = &tyre_rings[0];
    for j in 0..SEGMENTS {
        b.triangle(
            [inner_hub, first[j], first[(j + 1) % SEGMENTS]],
            centre + outward,
            "wheels",
        );
    }
}

fn ground(b: &mut Builder) {
    const HALF_SIZE: f64 = 15.0;
    const CELLS: usize = 60;
    let step = 2.0 * HALF_SIZE / CELLS as f64;
    let mut index = vec![vec![0u32; CELLS + 1]; CELLS + 1];
    for (i, row) in index.iter_mut().enumerate() {
        for (j, slot) in row.iter_mut().enumerate() {
            *slot = b.vertex(Vector3::new(
                -HALF_SIZE + i as f64 * step,
                -HALF_SIZE + j as f64 * step,
                0.0,
            ));
        }
    }
    for i in 0..CELLS {
        for j in 0..CELLS {
            let below = Vector3::new(
                -HALF_SIZE + (i as f64 + 0.5) * step,
                -HALF_SIZE + (j as f64 + 0.5) * step,
                -1.0,
            );
            let quad = [
                index[i][j],
                index[i + 1][j],
                index[i + 1][j + 1],
                index[i][j + 1],
            ];
            b.quad(quad, below, "ground");
        }
    }
}

/// The sedan and its ground plane.
pub fn sedan() -> RawMesh {
    let mut b = Builder {
        mesh: RawMesh::default(),
    };
    lower_body(&mut b);
    greenhouse(&mut b);
    for side in [1.0, -1.0] {
        for x in [WHEEL_X, -WHEEL_X] {
            wheel(&mut b, x, side);
        }
        // Door mirror at the base of the A-pillar.
        let y0 = side * 0.80;
        let y1 = side * 0.98;
        b.cuboid(
            Vector3::new(0.98, y0.min(y1), 1.00),
            Vector3::new(1.10, y0.max(y1), 1.10),
            "mirrors",
        );
        b.cuboid(
            Vector3::new(2.285, (side * 0.42).min(side * 0.58), 0.56),
            Vector3::new(2.305, (side * 0.42).max(side * 0.58), 0.64),
            "headlights",
        );
    }
    b.cuboid(
        Vector3::new(2.29, -0.36, 0.38),
        Vector3::new(2.31, 0.36, 0.54),
        "grille",
    );
    ground(&mut b);
    b.mesh
}

/// Writes the sedan as OBJ to `path`, atomically. Returns (vertices, triangles, parts).
pub fn write_car_obj(path: &Path) -> std::io::Result<(usize, usize, usize)> {
    let mesh = sedan();
    let header = "irpol procedural sedan on a ground plane (irpol::scene::car).\n\
                  Metres; z up; nose toward +x; left side toward +y; ground at z = 0.\n\
                  Groups are parts: give each a material and temperature in the scene TOML.";
    crate::atomic::write_atomically(path, format_obj(&mesh, header).as_bytes())?;
    Ok((mesh.positions.len(), mesh.faces.len(), mesh.parts.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sedan_has_the_expected_parts_and_proportions() {
        let mesh = sedan();
        let mut parts = mesh.used_parts();
        parts.sort_unstable();
        assert_eq!(
            parts,
            vec![
                "body",
                "bumpers",
                "grille",
                "ground",
                "headlights",
                "hood",
                "mirrors",
                "pillars",
                "rear_window",
                "roof",
                "side_windows",
                "trunk",
                "tyres",
                "wheels",
                "windshield"
            ]
        );
        let ground = mesh.part_index_of("ground");
        let car: Vec<&Vector3<f64>> = mesh
            .faces
            .iter()
            .filter(|f| Some(f.part) != ground)
            .flat_map(|f| f.vertices.map(|v| &mesh.positions[v as usize]))
            .collect();
        let max = |axis: usize| car.iter().map(|p| p[axis]).fold(f64::MIN, f64::max);
        let min = |axis: usize| car.iter().map(|p| p[axis]).fold(f64::MAX, f64::min);
        assert!((max(0) - min(0) - 4.62).abs() < 0.05, "length");
        assert!((max(1) - min(1) - 1.96).abs() < 0.05, "width with mirrors");
        assert!((max(2) - 1.49).abs() < 0.02, "height");
        assert!(min(2).abs() < 1e-9, "tyres touch the ground");
    }

    #[test]
    fn windshield_is_sloped_and_faces_forward_and_up() {
        let mesh = sedan();
        let part = mesh.part_index_of("windshield").unwrap();
        let mut normal = Vector3::zeros();
        for face in mesh.faces.iter().filter(|f| f.part == part) {
            let [a, b, c] = face.vertices.map(|v| mesh.positions[v as usize]);
            normal += (b - a).cross(&(c - a));
        }
        let n = normal.normalize();
        let tilt_from_vertical = n.z.asin().to_degrees();
        assert!(n.x > 0.0 && n.y.abs() < 1e-9);
        // A windshield raked ~30° from horizontal has its normal ~60° above the horizon.
        assert!(
            (55.0..68.0).contains(&tilt_from_vertical),
            "{tilt_from_vertical}"
        );
    }

    #[test]
    fn faces_point_out_of_the_car() {
        // Outward faces: the mean normal of each side of the car points to that side.
        let mesh = sedan();
        let ground = mesh.part_index_of("ground");
        let (mut left, mut right, mut up) = (Vector3::zeros(), Vector3::zeros(), 0.0);
        for face in mesh.faces.iter().filter(|f| Some(f.part) != ground) {
            let [a, b, c] = face.vertices.map(|v| mesh.positions[v as usize]);
            let n = (b - a).cross(&(c - a));
            let centroid = (a + b + c) / 3.0;
            if centroid.y > 0.85 {
                left += n;
            } else if centroid.y < -0.85 {
                right += n;
            }
            if centroid.z > 1.3 {
                up += n.z;
            }
        }
        assert!(left.y > 0.0 && right.y < 0.0 && up > 0.0);
    }
}
