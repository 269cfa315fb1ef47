//! Multi-jittered patterns (Chiu, Shirley and Wang, "Multi-jittered sampling", Graphics Gems IV,
//! 1994) for path counts that are not a power of two (module docs of [`super`]).

use rand::Rng;

/// n multi-jittered points in [0, 1)², in no particular order, from `rng`. The grid is m × k
/// with m the largest divisor of n not above √n (a prime n gives 1 × n: Latin-hypercube points).
pub fn multi_jittered(n: usize, rng: &mut impl Rng) -> Vec<[f64; 2]> {
    let columns = (1..=n)
        .take_while(|m| m * m <= n)
        .filter(|m| n.is_multiple_of(*m))
        .last()
        .unwrap_or(1);
    let rows = n / columns.max(1);
    // Fine stratum of u₀ of the point in column i, row j: i k + x_order[i][j]; of u₁:
    // j m + y_order[j][i]. Canonically x_order[i][j] = j and y_order[j][i] = i; shuffling each
    // column's x strata and each row's y strata keeps one point per cell and per stratum.
    let x_order: Vec<Vec<usize>> = (0..columns).map(|_| shuffled(rows, rng)).collect();
    let y_order: Vec<Vec<usize>> = (0..rows).map(|_| shuffled(columns, rng)).collect();
    let mut points = Vec::with_capacity(n);
    for j in 0..rows {
        for i in 0..columns {
            let x_stratum = i * rows + x_order[i][j];
            let y_stratum = j * columns + y_order[j][i];
            points.push([
                (x_stratum as f64 + rng.random::<f64>()) / n as f64,
                (y_stratum as f64 + rng.random::<f64>()) / n as f64,
            ]);
        }
    }
    points
}

/// 0..count in random order (Fisher–Yates).
pub fn shuffled(count: usize, rng: &mut impl Rng) -> Vec<usize> {
    let mut order: Vec<usize> = (0..count).collect();
    for a in (1..count).rev() {
        order.swap(a, rng.random_range(0..=a));
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Index of the stratum of `value` among `count` equal ones.
    fn stratum(value: f64, count: usize) -> usize {
        (value * count as f64) as usize
    }

    #[test]
    fn every_stratum_and_every_cell_holds_one_point() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for (n, m, k) in [(1, 1, 1), (7, 1, 7), (12, 3, 4), (16, 4, 4), (1024, 32, 32)] {
            let points = multi_jittered(n, &mut rng);
            assert_eq!(points.len(), n);
            let mut x = vec![0; n];
            let mut y = vec![0; n];
            let mut cells = vec![0; n];
            for p in &points {
                assert!((0.0..1.0).contains(&p[0]) && (0.0..1.0).contains(&p[1]));
                x[stratum(p[0], n)] += 1;
                y[stratum(p[1], n)] += 1;
                cells[stratum(p[0], m) * k + stratum(p[1], k)] += 1;
            }
            assert!(x.iter().chain(&y).chain(&cells).all(|&c| c == 1), "n = {n}");
        }
    }
}
