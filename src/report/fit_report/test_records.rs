//! Fit records for unit tests, built through serde from a few given fields over neutral
//! defaults, so that fields the fit engine adds later (with serde defaults) do not break them.

use crate::material::FitRecord;
use serde_json::{json, Value};

/// A [`FitRecord`] with `fields` (a JSON object) over a minimal valid record.
pub fn fit_record(fields: Value) -> FitRecord {
    let mut record = json!({
        "source": "x.csv",
        "source_sha256": "",
        "points": 0,
        "elements": [],
        "free_parameters": [],
        "optimizer": "nm",
        "seed": 0,
        "settings": {},
        "iterations": 0,
        "evaluations": 0,
        "cost": 1.0,
        "reduced_chi2": 1.0,
        "degrees_of_freedom": 1,
        "aic": 0.0,
        "bic": 0.0,
        "termination": "",
        "rmse": {},
        "uncertainty": {},
        "correlation": [],
        "alternative": null,
    });
    if let (Value::Object(base), Value::Object(given)) = (&mut record, fields) {
        base.extend(given);
    }
    serde_json::from_value(record).expect("a valid fit record")
}
