"""Cross-check of `irpol fit` against NLopt on an independent numpy form of the model.

    .venv/bin/python scripts/crosscheck_nlopt.py [--irpol PATH] [--files measurements/*.csv]

For each measurement file:
1. re-checks the model used here: the fast vectorized form (crosscheck_common.FastModel) against
   scripts/pbrdf_numpy.py on the file's geometries, and pbrdf_numpy against NIST SCATMECH on a few
   of them (all to 1e-9 relative to m00);
2. runs `irpol fit FILE --out TMP --reports TMP2` (wall clock timed) and reads the material TOML;
3. minimizes the same weighted least squares, chi2 = sum(((model - data)/u)^2) over every Mueller
   element in the file (u from its u_ columns), with NLopt, using the distribution irpol chose,
   Smith shadowing and irpol's default free parameters (sigma, q, n, k, rho_d; no q for the
   Gaussian), bounds (sigma in [0.005, 1.5], q in [1.51, 50] with Smith, n in [0.05, 10], k in [0, 50],
   rho_d in [0, 1]) and search coordinates (ln sigma, ln(q - 1), n, asinh(k/0.1), rho_d):
     (a) "NM":      LN_NELDERMEAD from irpol's local start sigma 0.2, q 3, n 1.8, k 0.1, rho_d 0.02,
                    initial step 10 % of each search-box width, restarted from its own result until a
                    restart gains < 1e-9 relative (at most 5 restarts);
     (b) "CRS2+NM": GN_CRS2_LM over the whole box (nlopt.srand(seed), population 10 (d + 1),
                    at most --crs-maxeval evaluations), then the Nelder-Mead polish of (a).

PASS for a file when all of
  * irpol's reported cost equals chi2 recomputed here at irpol's parameters (relative 1e-6) and
    reduced_chi2 = cost / degrees_of_freedom with degrees_of_freedom = observations - free;
  * irpol's cost <= min(NM, CRS2+NM) * (1 + 1e-3);
  * every free parameter agrees with the best NLopt result within max(2 sigma_irpol, 1e-6 max(1, |p|)),
    sigma_irpol being irpol's reported 1-sigma ([fit.uncertainty]); the floor only matters if irpol
    reports no or a zero uncertainty;
  * when irpol fitted both distributions and kept one ([fit.alternative]), the other one's cost is
    also <= NLopt's best for that distribution (both runs) * (1 + 1e-3), so that the AIC choice
    compares two converged fits.
Exit status 0 when every file passes, 1 when one fails, 2 on setup problems (no irpol binary, an
unreadable file, a model check failing).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass

import nlopt
import numpy as np

import crosscheck_common as cc

COST_TOLERANCE = 1e-3
RECOMPUTE_TOLERANCE = 1e-6
PARAMETER_FLOOR = 1e-6


@dataclass
class NloptResult:
    cost: float
    params: dict[str, float]
    evaluations: int
    seconds: float


class Objective:
    """chi2 as a function of the free parameters' search coordinates; remembers the best point,
    so a run that NLopt stops with an exception (round-off) still yields its best result."""

    def __init__(self, fast: cc.FastModel, free: list[str]):
        self.fast = fast
        self.free = free
        self.evaluations = 0
        self.best_cost = math.inf
        self.best_x: np.ndarray | None = None

    def physical(self, x) -> np.ndarray:
        values = dict(cc.FIXED_DEFAULTS)
        for name, coord in zip(self.free, x):
            lo, hi = cc.BOUNDS[name]
            values[name] = float(np.clip(cc.from_search(name, coord), lo, hi))
        return np.array([values[p] for p in cc.PARAMETERS])

    def __call__(self, x, grad) -> float:
        self.evaluations += 1
        cost = self.fast.chi2(self.physical(x))
        if not math.isfinite(cost):
            cost = 1e300
        if cost < self.best_cost:
            self.best_cost, self.best_x = cost, np.array(x, dtype=float)
        return cost

    def box(self) -> tuple[np.ndarray, np.ndarray]:
        lo = np.array([float(cc.to_search(p, cc.BOUNDS[p][0])) for p in self.free])
        hi = np.array([float(cc.to_search(p, cc.BOUNDS[p][1])) for p in self.free])
        return lo, hi


def _run(opt: nlopt.opt, objective: Objective, x0: np.ndarray) -> None:
    try:
        opt.optimize(x0)
    except nlopt.RoundoffLimited:
        pass  # the best point so far is kept by the objective


def nelder_mead(objective: Objective, x0: np.ndarray, max_restarts: int = 5) -> None:
    lo, hi = objective.box()
    x = np.clip(x0, lo, hi)
    previous = math.inf
    for _ in range(1 + max_restarts):
        opt = nlopt.opt(nlopt.LN_NELDERMEAD, len(x))
        opt.set_lower_bounds(lo)
        opt.set_upper_bounds(hi)
        opt.set_min_objective(objective)
        opt.set_initial_step(0.1 * (hi - lo))
        opt.set_ftol_rel(1e-12)
        opt.set_xtol_rel(1e-10)
        opt.set_maxeval(20000)
        _run(opt, objective, x)
        x = objective.best_x.copy()
        if previous - objective.best_cost <= 1e-9 * objective.best_cost:
            break
        previous = objective.best_cost


def fit_nm(fast: cc.FastModel, free: list[str]) -> NloptResult:
    objective = Objective(fast, free)
    t0 = time.perf_counter()
    nelder_mead(objective, np.array([float(cc.to_search(p, cc.START[p])) for p in free]))
    return _result(objective, time.perf_counter() - t0)


def fit_crs2_nm(fast: cc.FastModel, free: list[str], seed: int, maxeval: int) -> NloptResult:
    objective = Objective(fast, free)
    lo, hi = objective.box()
    t0 = time.perf_counter()
    nlopt.srand(seed)
    opt = nlopt.opt(nlopt.GN_CRS2_LM, len(free))
    opt.set_lower_bounds(lo)
    opt.set_upper_bounds(hi)
    opt.set_min_objective(objective)
    opt.set_population(10 * (len(free) + 1))
    opt.set_ftol_rel(1e-10)
    opt.set_maxeval(maxeval)
    _run(opt, objective, 0.5 * (lo + hi))
    nelder_mead(objective, objective.best_x.copy())
    return _result(objective, time.perf_counter() - t0)


def _result(objective: Objective, seconds: float) -> NloptResult:
    p = objective.physical(objective.best_x)
    params = {name: float(p[cc.PARAMETERS.index(name)]) for name in objective.free}
    return NloptResult(objective.best_cost, params, objective.evaluations, seconds)


# ---------------------------------------------------------------------------------------------


@dataclass
class FileOutcome:
    name: str
    distribution: str
    irpol: cc.IrpolFit | None
    recomputed: float | None
    nm: NloptResult
    crs: NloptResult
    failures: list[str]
    model_check: str
    alternative: tuple[str, float, float] | None = None  # distribution, irpol cost, nlopt best cost


def irpol_vector(fit: cc.IrpolFit) -> np.ndarray:
    values = dict(cc.FIXED_DEFAULTS)
    for p in cc.PARAMETERS:
        if p in fit.model:
            values[p] = float(fit.model[p])
    return np.array([values[p] for p in cc.PARAMETERS])


def check_file(path: str, irpol: str | None, distribution: str, seed: int, crs_maxeval: int,
               irpol_args: list[str]) -> FileOutcome:
    m = cc.read_measurement(path)
    fit = cc.run_irpol_fit(irpol, path, irpol_args) if irpol else None
    if fit is not None:
        distribution = fit.distribution
        if fit.model.get("shadowing", "smith") != "smith":
            raise cc.SetupError(f"{m.name}: irpol used shadowing {fit.model.get('shadowing')}, this check assumes smith")
    model_check = cc.check_model(m, distribution, seed)
    fast = cc.FastModel(m, distribution)
    free = cc.free_parameters(distribution)
    nm = fit_nm(fast, free)
    crs = fit_crs2_nm(fast, free, seed, crs_maxeval)
    failures: list[str] = []
    recomputed = None
    alternative = None
    if fit is not None:
        failures += compare(m, fast, fit, free, nm, crs)
        recomputed = fast.chi2(irpol_vector(fit))
        alternative = check_alternative(m, fit, seed, crs_maxeval, failures)
    return FileOutcome(m.name, distribution, fit, recomputed, nm, crs, failures, model_check, alternative)


def check_alternative(m: cc.Measurement, fit: cc.IrpolFit, seed: int, crs_maxeval: int,
                      failures: list[str]) -> tuple[str, float, float] | None:
    """irpol keeps the distribution with the lower AIC; that choice is only sound if the other
    family was fitted as well. Refits it (both NLopt runs) and requires the same cost tolerance."""
    alt = fit.fit.get("alternative")
    if not alt:
        return None
    distribution = alt["model"]["distribution"]
    fast = cc.FastModel(m, distribution)
    free = cc.free_parameters(distribution)
    best = min(fit_nm(fast, free).cost, fit_crs2_nm(fast, free, seed, crs_maxeval).cost)
    cost = float(alt["cost"])
    if cost > best * (1 + COST_TOLERANCE):
        failures.append(f"irpol's {distribution} alternative cost {cost:.6g} > nlopt's best {best:.6g} "
                        f"x (1 + {COST_TOLERANCE:g}): the model choice compares against an unconverged fit")
    return distribution, cost, best


def compare(m: cc.Measurement, fast: cc.FastModel, fit: cc.IrpolFit, free: list[str],
            nm: NloptResult, crs: NloptResult) -> list[str]:
    failures = []
    f = fit.fit
    cost = float(f["cost"])
    if sorted(fit.free) != sorted(free):
        failures.append(f"irpol's free parameters {fit.free} differ from the default set {free}")
    recomputed = fast.chi2(irpol_vector(fit))
    if abs(cost - recomputed) > RECOMPUTE_TOLERANCE * recomputed:
        failures.append(f"irpol's cost {cost:.8g} != chi2 {recomputed:.8g} recomputed at its parameters")
    dof = m.observations - len(fit.free)
    if int(f.get("degrees_of_freedom", -1)) != dof:
        failures.append(f"degrees_of_freedom {f.get('degrees_of_freedom')} != {m.observations} - {len(fit.free)}")
    if "reduced_chi2" in f and abs(float(f["reduced_chi2"]) - cost / dof) > 1e-6 * cost / dof:
        failures.append(f"reduced_chi2 {f['reduced_chi2']} != cost / dof = {cost / dof:.8g}")
    best = nm if nm.cost <= crs.cost else crs
    if cost > best.cost * (1 + COST_TOLERANCE):
        failures.append(f"irpol's cost {cost:.6g} > nlopt's best {best.cost:.6g} x (1 + {COST_TOLERANCE:g})")
    for p in free:
        value = fit.value(p)
        sigma = fit.uncertainty(p)
        tol = max(2.0 * sigma if sigma else 0.0, PARAMETER_FLOOR * max(1.0, abs(value)))
        if not abs(value - best.params[p]) <= tol:
            failures.append(f"{p}: irpol {value:.6g} vs nlopt {best.params[p]:.6g}, |diff| "
                            f"{abs(value - best.params[p]):.3g} > {tol:.3g}")
    return failures


def print_tables(outcomes: list[FileOutcome]) -> None:
    print()
    print(f"{'material':<16}{'dist':<9}{'irpol cost':>15}{'recomputed':>15}{'NM cost':>15}{'CRS2+NM cost':>15}"
          f"{'irpol/best-1':>13}{'irpol s':>9}{'nlopt s':>9}{'nlopt/irpol':>12}{'NM evals':>9}{'CRS evals':>10}  verdict")
    for o in outcomes:
        best = min(o.nm.cost, o.crs.cost)
        ic = f"{float(o.irpol.fit['cost']):.10g}" if o.irpol else "-"
        rc = f"{o.recomputed:.10g}" if o.recomputed is not None else "-"
        rel = f"{float(o.irpol.fit['cost']) / best - 1:.1e}" if o.irpol else "-"
        iw = f"{o.irpol.wall_seconds:.2f}" if o.irpol else "-"
        ratio = f"{o.crs.seconds / o.irpol.wall_seconds:.2f}" if o.irpol else "-"
        verdict = "-" if not o.irpol else ("PASS" if not o.failures else "FAIL")
        print(f"{o.name:<16}{o.distribution:<9}{ic:>15}{rc:>15}{o.nm.cost:>15.10g}{o.crs.cost:>15.10g}"
              f"{rel:>13}{iw:>9}{o.crs.seconds:>9.2f}{ratio:>12}{o.nm.evaluations:>9}{o.crs.evaluations:>10}  {verdict}")
    print()
    print(f"{'material':<16}{'param':<7}{'irpol':>13}{'1-sigma':>11}{'NM':>13}{'CRS2+NM':>13}{'|diff|/sigma':>14}")
    for o in outcomes:
        best = o.nm if o.nm.cost <= o.crs.cost else o.crs
        for p in o.nm.params:
            iv = o.irpol.value(p) if o.irpol else None
            s = o.irpol.uncertainty(p) if o.irpol else None
            z = f"{abs(iv - best.params[p]) / s:.1e}" if (iv is not None and s) else "-"
            print(f"{o.name:<16}{p:<7}{(f'{iv:.6g}' if iv is not None else '-'):>13}"
                  f"{(f'{s:.3g}' if s else '-'):>11}{o.nm.params[p]:>13.6g}{o.crs.params[p]:>13.6g}{z:>14}")
    alternatives = [o for o in outcomes if o.alternative]
    if alternatives:
        print()
        print(f"{'material':<16}{'alternative':<13}{'irpol cost':>15}{'nlopt best':>15}{'irpol/best-1':>13}")
        for o in alternatives:
            d, cost, best = o.alternative
            print(f"{o.name:<16}{d:<13}{cost:>15.10g}{best:>15.10g}{cost / best - 1:>13.1e}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--irpol", help="path to the irpol binary (default: $IRPOL, target dirs, PATH)")
    ap.add_argument("--files", nargs="+", default=cc.SHIPPED, help="measurement CSVs (default: measurements/*.csv)")
    ap.add_argument("--seed", type=int, default=20240611, help="seed of CRS2 and of the model checks")
    ap.add_argument("--crs-maxeval", type=int, default=40000)
    ap.add_argument("--irpol-args", default="", help="extra arguments for `irpol fit`, one string")
    ap.add_argument("--no-irpol", action="store_true",
                    help="only run the NLopt fits (with --distribution), no comparison")
    ap.add_argument("--distribution", default="cauchy", choices=("cauchy", "gaussian"),
                    help="distribution of the NLopt fits with --no-irpol")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    outcomes: list[FileOutcome] = []
    try:
        irpol = None if args.no_irpol else cc.find_irpol(args.irpol)
        for path in args.files:
            o = check_file(path, irpol, args.distribution, args.seed, args.crs_maxeval, args.irpol_args.split())
            print(f"{o.name}: {o.model_check}; "
                  + ("PASS" if o.irpol and not o.failures else "FAIL" if o.irpol else "fitted"), flush=True)
            for msg in o.failures:
                print(f"  FAIL {o.name}: {msg}")
            outcomes.append(o)
    except cc.SetupError as e:
        print(f"setup error: {e}", file=sys.stderr)
        return 2
    print_tables(outcomes)
    print(f"\n(total {time.perf_counter() - t_start:.1f} s)")
    if args.no_irpol:
        print(f"0 passed, 0 failed ({len(outcomes)} files fitted without irpol)")
        return 0
    failed = sum(1 for o in outcomes if o.failures)
    print(f"{len(outcomes) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
