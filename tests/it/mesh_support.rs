//! Binary PLY grids written from known arrays, for the PLY reader's tests, its benchmark
//! (`benches/mesh.rs`) and the memory example (`examples/mesh_memory.rs`): a square grid in
//! z = 0 with a slight bump, optional normals and a per-vertex `temperature`, faces as
//! `property list uchar int vertex_indices` (two triangles per cell).
#![allow(dead_code)]

/// What a grid PLY holds.
#[derive(Clone, Copy, Debug)]
pub struct GridPly {
    /// Cells per side: 2·cells² triangles, (cells + 1)² vertices.
    pub cells: usize,
    pub big_endian: bool,
    pub normals: bool,
    pub temperature: bool,
}

impl GridPly {
    /// The grid with about `triangles` triangles (at least that many).
    pub fn with_triangles(triangles: usize, big_endian: bool) -> GridPly {
        let cells = ((triangles as f64 / 2.0).sqrt().ceil() as usize).max(1);
        GridPly {
            cells,
            big_endian,
            normals: true,
            temperature: true,
        }
    }

    pub fn triangles(&self) -> usize {
        2 * self.cells * self.cells
    }

    /// Vertex `i` of the grid: its position, normal and temperature (K), the values the file
    /// holds as f32.
    pub fn vertex(&self, i: usize) -> ([f32; 3], [f32; 3], f32) {
        let side = self.cells + 1;
        let (u, v) = ((i % side) as f32, (i / side) as f32);
        let z = 0.01 * ((u * 0.37).sin() + (v * 0.23).cos());
        (
            [u / self.cells as f32, v / self.cells as f32, z],
            [0.0, 0.0, 1.0],
            280.0 + 0.01 * (i % 4000) as f32,
        )
    }

    /// The triangles' vertex indices, two per cell.
    pub fn face(&self, t: usize) -> [u32; 3] {
        let (cell, second) = (t / 2, t % 2 == 1);
        let side = self.cells + 1;
        let (i, j) = (cell % self.cells, cell / self.cells);
        let index = |i: usize, j: usize| (j * side + i) as u32;
        let (a, b, c, d) = (
            index(i, j),
            index(i + 1, j),
            index(i + 1, j + 1),
            index(i, j + 1),
        );
        if second {
            [a, c, d]
        } else {
            [a, b, c]
        }
    }

    /// The whole file.
    pub fn bytes(&self) -> Vec<u8> {
        let side = self.cells + 1;
        let vertices = side * side;
        let mut header = format!(
            "ply\nformat binary_{}_endian 1.0\ncomment irpol test grid\nelement vertex {vertices}\n\
             property float x\nproperty float y\nproperty float z\n",
            if self.big_endian { "big" } else { "little" }
        );
        if self.normals {
            header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
        }
        if self.temperature {
            header.push_str("property float temperature\n");
        }
        header.push_str(&format!(
            "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            self.triangles()
        ));
        let per_vertex = 4 * (3 + 3 * usize::from(self.normals) + usize::from(self.temperature));
        let mut out =
            Vec::with_capacity(header.len() + vertices * per_vertex + self.triangles() * 13);
        out.extend_from_slice(header.as_bytes());
        let f32_bytes = |x: f32| {
            if self.big_endian {
                x.to_be_bytes()
            } else {
                x.to_le_bytes()
            }
        };
        for i in 0..vertices {
            let (p, n, t) = self.vertex(i);
            p.iter().for_each(|&x| out.extend_from_slice(&f32_bytes(x)));
            if self.normals {
                n.iter().for_each(|&x| out.extend_from_slice(&f32_bytes(x)));
            }
            if self.temperature {
                out.extend_from_slice(&f32_bytes(t));
            }
        }
        for t in 0..self.triangles() {
            out.push(3);
            for v in self.face(t) {
                let v = v as i32;
                out.extend_from_slice(&if self.big_endian {
                    v.to_be_bytes()
                } else {
                    v.to_le_bytes()
                });
            }
        }
        out
    }
}
