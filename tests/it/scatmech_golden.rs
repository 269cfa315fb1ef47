//! The pBRDF against NIST SCATMECH: golden Mueller matrices from `scripts/scatmech_reference.py`
//! (both distributions, shadowing none / Torrance–Sparrow / Smith through SCATMECH's tabulated
//! shadow function, dielectrics and a metal, in-plane, out-of-plane, normal incidence, up to 89°).
//! m00 must agree to 1e-9 relative and every other element to 1e-9·m00.

use irpol::optics::RefractiveIndex;
use irpol::pbrdf::{Direction, Pbrdf, Shadowing, SlopeDistribution};
use std::collections::HashMap;

#[test]
fn mueller_matrices_match_scatmech_golden_values() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/scatmech_golden.csv"
    );
    let mut reader = csv::Reader::from_path(path).expect("golden file");
    let headers = reader.headers().unwrap().clone();
    let col: HashMap<&str, usize> = headers.iter().enumerate().map(|(i, h)| (h, i)).collect();
    let (mut rows, mut worst_m00, mut worst_other) = (0, 0.0f64, 0.0f64);
    let mut by_shadowing: HashMap<String, usize> = HashMap::new();
    for record in reader.records() {
        let record = record.unwrap();
        let num = |name: &str| record[col[name]].parse::<f64>().unwrap();
        let sigma = num("sigma");
        let distribution = match &record[col["distribution"]] {
            "cauchy" => SlopeDistribution::Cauchy { sigma, q: num("q") },
            "gaussian" => SlopeDistribution::Gaussian { sigma },
            other => panic!("unknown distribution {other}"),
        };
        let shadowing = Shadowing::parse(&record[col["shadowing"]]).unwrap();
        *by_shadowing.entry(shadowing.name().to_owned()).or_default() += 1;
        let model = Pbrdf::new(
            distribution,
            shadowing,
            RefractiveIndex::new(num("n"), num("k")),
            0.0,
        )
        .unwrap();
        let incident = Direction::from_angles(
            num("theta_i_deg").to_radians(),
            num("phi_i_deg").to_radians(),
        );
        let scattered = Direction::from_angles(
            num("theta_r_deg").to_radians(),
            num("phi_r_deg").to_radians(),
        );
        let got = model.mueller(&incident, &scattered);
        let m00 = num("m00");
        let rel = (got[(0, 0)] - m00).abs() / m00;
        worst_m00 = worst_m00.max(rel);
        assert!(
            rel < 1e-9,
            "row {}: m00 {} vs SCATMECH {m00} ({distribution:?} {shadowing:?})",
            rows + 2,
            got[(0, 0)]
        );
        for r in 0..4 {
            for c in 0..4 {
                let want = num(&format!("m{r}{c}"));
                let err = (got[(r, c)] - want).abs() / m00;
                worst_other = worst_other.max(err);
                assert!(
                    err < 1e-9,
                    "row {}: m{r}{c} {} vs SCATMECH {want} (m00 {m00})",
                    rows + 2,
                    got[(r, c)]
                );
            }
        }
        rows += 1;
    }
    assert!(rows >= 2000, "only {rows} golden rows");
    for shadowing in ["none", "torrance-sparrow", "smith"] {
        assert!(
            by_shadowing.get(shadowing).copied().unwrap_or(0) >= 100,
            "few {shadowing} rows: {by_shadowing:?}"
        );
    }
    println!("{rows} rows; worst m00 rel {worst_m00:.2e}, worst other/m00 {worst_other:.2e}");
}
