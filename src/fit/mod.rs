//! Fitting pBRDF models to Mueller-matrix measurements (DESIGN §3, `src/fit/`): objective and
//! parameter transforms, the genetic global stage, the Nelder–Mead polish, uncertainties and
//! model comparison.

pub mod genetic;
