//! The binary hierarchy collapsed into nodes of four children (a BVH4, as Embree and pbrt's
//! wide trees): a ray tests four boxes per node in one vectorized loop instead of two per node
//! one after the other, and its path from the root is about half as long.

use super::build::Node;

/// Children per node.
pub const LANES: usize = 4;

/// Four children's boxes in structure-of-arrays form (`bounds[0]` the low corners and
/// `bounds[1]` the high ones, `[axis][lane]`), so that the slab test of all four is one loop
/// over lanes that LLVM turns into vector instructions; bounds in f32 rounded outward (copied
/// from the binary nodes). A lane's `child` is the node it points to, or a leaf's first
/// triangle (in leaf order) when its `count` (the leaf's triangles) is not 0. An unused lane
/// has the inverted box from +∞ to −∞, which no ray enters (see `Ray::entries`). 128 bytes:
/// two cache lines, where the binary tree read a 32-byte node per box.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Wide {
    pub bounds: [[[f32; LANES]; 3]; 2],
    pub child: [u32; LANES],
    pub count: [u32; LANES],
}

impl Wide {
    const EMPTY: Wide = Wide {
        bounds: [[[f32::INFINITY; LANES]; 3], [[f32::NEG_INFINITY; LANES]; 3]],
        child: [0; LANES],
        count: [0; LANES],
    };

    /// Whether `lane` holds a child.
    #[cfg(test)]
    pub fn used(&self, lane: usize) -> bool {
        self.bounds[0][0][lane] != f32::INFINITY
    }
}

/// The wide nodes over the binary tree `binary` (depth first, its root first), the root first:
/// each wide node holds a binary node's children and, while it has fewer than four lanes, the
/// children of its largest interior lane in place of that lane (the one a ray most likely
/// enters, so that the most likely node tests are the ones merged). A binary tree that is a
/// single leaf gives a root with that leaf in one lane. Also returns the depth (the most wide
/// nodes on a path from the root), which bounds the traversal's stack.
pub fn collapse(binary: &[Node]) -> (Vec<Wide>, usize) {
    // Each wide node stands for a distinct binary interior node (or the root leaf): at most
    // half the binary nodes, usually a quarter to a third. Reserved at the bound so that the
    // vector never moves; the pages never written are never mapped in.
    let mut out = Vec::with_capacity(binary.len() / 2 + 1);
    let depth = if binary.is_empty() {
        0
    } else {
        append(binary, 0, &mut out).1
    };
    (out, depth)
}

/// Appends the wide node for binary node `at` and its subtrees (depth first) to `out`; returns
/// its index and the depth of its subtree.
fn append(binary: &[Node], at: usize, out: &mut Vec<Wide>) -> (u32, usize) {
    let (lanes, used) = lanes(binary, at);
    let index = out.len();
    out.push(Wide::EMPTY);
    let mut depth = 1;
    for (lane, &b) in lanes[..used].iter().enumerate() {
        let node = &binary[b];
        let (child, count) = if node.count() > 0 {
            (node.link, node.triangles)
        } else {
            let (child, below) = append(binary, b, out);
            depth = depth.max(1 + below);
            (child, 0)
        };
        let wide = &mut out[index];
        for axis in 0..3 {
            wide.bounds[0][axis][lane] = node.lo[axis];
            wide.bounds[1][axis][lane] = node.hi[axis];
        }
        (wide.child[lane], wide.count[lane]) = (child, count);
    }
    (index as u32, depth)
}

/// The binary nodes (indices, and how many) that become the lanes of binary node `at`'s wide
/// node: its children, the largest interior one opened while lanes remain. In increasing
/// index, so that the collapse reads the binary tree in its depth-first order (sequentially,
/// where the opening order jumped about and the collapse waited on memory), and the lanes' and
/// the leaves' orders agree.
fn lanes(binary: &[Node], at: usize) -> ([usize; LANES], usize) {
    let children = |at: usize| [at + 1, at + binary[at].link as usize];
    let mut lanes = [0usize; LANES];
    let mut used = if binary[at].count() > 0 {
        lanes[0] = at;
        1
    } else {
        lanes[..2].copy_from_slice(&children(at));
        2
    };
    while used < LANES {
        let interior = (0..used).filter(|&k| binary[lanes[k]].count() == 0);
        let area = |k: usize| half_area(&binary[lanes[k]]);
        let Some(open) = interior.max_by(|&a, &b| area(a).total_cmp(&area(b))) else {
            break;
        };
        [lanes[open], lanes[used]] = children(lanes[open]);
        used += 1;
    }
    lanes[..used].sort_unstable();
    (lanes, used)
}

/// Half the surface area of a binary node's box (only compared).
fn half_area(node: &Node) -> f32 {
    let [x, y, z] = std::array::from_fn(|a| node.hi[a] - node.lo[a]);
    x * y + y * z + z * x
}
