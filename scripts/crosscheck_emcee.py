"""Cross-check of irpol's fit uncertainties against an MCMC posterior (emcee).

    .venv/bin/python scripts/crosscheck_emcee.py [--irpol PATH] [--file measurements/paper_paint.csv ...]

For each file:
1. checks the model used here (fast form vs scripts/pbrdf_numpy.py vs SCATMECH, as in
   crosscheck_nlopt.py) and runs `irpol fit FILE` into temporary folders;
2. samples the posterior of irpol's free parameters for the distribution irpol chose, with Smith
   shadowing: flat priors on the physical parameters within irpol's bounds (sigma in [0.005, 1.5],
   q in [1.51, 50], n in [0.05, 10], k in [0, 50], rho_d in [0, 1]) and log-likelihood -chi2/2,
   chi2 = sum(((model - data)/u)^2) over every Mueller element in the file with the file's u_
   columns.  emcee's EnsembleSampler with differential-evolution moves (80 % DEMove,
   20 % DESnookerMove), the log-probability vectorized over walkers.  Walkers start from a
   Gaussian around an independent NLopt Nelder-Mead fit (not irpol's) with this side's own
   Gauss-Newton covariance, folded into the box.  Burn-in --burn steps are discarded; the
   production chain must be at least 50 integrated autocorrelation times long for every parameter
   (otherwise the run is a setup problem: raise --steps).  All random numbers are seeded (--seed).
3. PASS when, for every free parameter, irpol's 1-sigma ([fit.uncertainty]) is within a factor
   1.5 of the posterior standard deviation, and irpol's estimate lies inside the central 95 %
   posterior interval.
   Parameters on a bound: when irpol's estimate lies within 0.5 sigma_irpol of a bound (e.g.
   rho_d = 0 for a surface without a diffuse part) the flat prior truncates the posterior there. It
   is then no Gaussian: a half-normal has a standard deviation of 0.60 sigma and its central 95 %
   interval excludes the bound where the estimate sits.  For such parameters the one-sided forms are
   used: sigma_irpol within a factor 1.5 of the one-sided 68.27 % width |q_68.27 - bound| (equal to
   sigma for a half-normal), and the estimate inside the one-sided 95 % interval [bound, q_95].
   The table marks them and shows the plain standard deviation as well.
   Note: irpol scales its covariance by the reduced chi2, the likelihood here is not scaled; for the
   shipped files reduced chi2 is 0.99-1.01, so the difference is < 1 %.
Exit status 0 on pass, 1 on a failure, 2 on setup problems.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass

import emcee
import numpy as np

import crosscheck_common as cc
import crosscheck_nlopt as cn

ERROR_FACTOR = 1.5
BOUND_PROXIMITY = 0.5  # in units of sigma_irpol
MIN_CHAIN_PER_TAU = 50.0
ONE_SIGMA = 100.0 * math.erf(1.0 / math.sqrt(2.0))  # 68.27 %


@dataclass
class ParameterRow:
    name: str
    irpol_value: float | None
    irpol_sigma: float | None
    gauss_newton_sigma: float
    mean: float
    std: float
    central95: tuple[float, float]
    bound: float | None  # the bound irpol's estimate is at, if any
    one_sided_width: float | None
    one_sided95: tuple[float, float] | None
    tau: float
    failures: list[str]


@dataclass
class Sampled:
    name: str
    distribution: str
    rows: list[ParameterRow]
    seconds: float
    steps: int
    walkers: int
    acceptance: float
    irpol_seconds: float | None
    model_check: str


def sample(path: str, irpol: str | None, distribution: str, walkers: int, burn: int, steps: int,
           seed: int) -> Sampled:
    m = cc.read_measurement(path)
    fit = cc.run_irpol_fit(irpol, path) if irpol else None
    if fit is not None:
        distribution = fit.distribution
        if fit.model.get("shadowing", "smith") != "smith":
            raise cc.SetupError(f"{m.name}: irpol used shadowing {fit.model.get('shadowing')}, this check assumes smith")
    model_check = cc.check_model(m, distribution, seed)
    fast = cc.FastModel(m, distribution)
    free = cc.free_parameters(distribution)
    if fit is not None and sorted(fit.free) != sorted(free):
        raise cc.SetupError(f"{m.name}: irpol fitted {fit.free}, this check samples the default set {free}")
    lo = np.array([cc.BOUNDS[p][0] for p in free])
    hi = np.array([cc.BOUNDS[p][1] for p in free])

    def log_probability(x):
        x = np.atleast_2d(x)
        out = np.full(len(x), -np.inf)
        inside = np.all((x >= lo) & (x <= hi), axis=1)
        if inside.any():
            out[inside] = -0.5 * fast.chi2_batch(cc.full_parameters(free, x[inside], cc.FIXED_DEFAULTS))
        return out

    t0 = time.perf_counter()
    best = cn.fit_nm(fast, free)
    x_best = np.array([best.params[p] for p in free])
    cov = cc.gauss_newton_covariance(fast, free, x_best, cc.FIXED_DEFAULTS)
    rng = np.random.default_rng(seed)
    start = rng.multivariate_normal(x_best, cov, size=walkers)
    start = np.where(start < lo, 2 * lo - start, start)  # fold into the box
    start = np.where(start > hi, 2 * hi - start, start)
    sampler = emcee.EnsembleSampler(walkers, len(free), log_probability, vectorize=True,
                                    moves=[(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)])
    sampler.random_state = np.random.RandomState(seed).get_state()
    sampler.run_mcmc(start, burn + steps)
    seconds = time.perf_counter() - t0
    tau = sampler.get_autocorr_time(discard=burn, tol=0)
    if steps < MIN_CHAIN_PER_TAU * tau.max():
        raise cc.SetupError(f"{m.name}: production chain of {steps} steps is shorter than {MIN_CHAIN_PER_TAU:g} "
                            f"autocorrelation times (tau = {np.array2string(tau, precision=1)}); raise --steps")
    chain = sampler.get_chain(discard=burn, flat=True)
    rows = [_row(p, i, chain[:, i], fit, math.sqrt(cov[i, i]), float(tau[i])) for i, p in enumerate(free)]
    return Sampled(m.name, distribution, rows, seconds, steps, walkers, float(sampler.acceptance_fraction.mean()),
                   fit.wall_seconds if fit else None, model_check)


def _row(name: str, i: int, x: np.ndarray, fit: cc.IrpolFit | None, gn_sigma: float, tau: float) -> ParameterRow:
    lo, hi = cc.BOUNDS[name]
    central = (float(np.percentile(x, 2.5)), float(np.percentile(x, 97.5)))
    row = ParameterRow(name, None, None, gn_sigma, float(x.mean()), float(x.std()), central, None, None, None, tau, [])
    if fit is None:
        return row
    value, sigma = fit.value(name), fit.uncertainty(name)
    row.irpol_value, row.irpol_sigma = value, sigma
    if not sigma or not math.isfinite(sigma) or sigma <= 0:
        row.failures.append(f"irpol reports no usable 1-sigma ({sigma})")
        return row
    if value - lo <= BOUND_PROXIMITY * sigma:
        row.bound = lo
        q68, q95 = np.percentile(x, [ONE_SIGMA, 95.0])
        row.one_sided_width, row.one_sided95 = float(q68 - lo), (lo, float(q95))
    elif hi - value <= BOUND_PROXIMITY * sigma:
        row.bound = hi
        q68, q95 = np.percentile(x, [100.0 - ONE_SIGMA, 5.0])
        row.one_sided_width, row.one_sided95 = float(hi - q68), (float(q95), hi)
    width = row.one_sided_width if row.bound is not None else row.std
    interval = row.one_sided95 if row.bound is not None else central
    ratio = sigma / width if width > 0 else math.inf
    if not (1.0 / ERROR_FACTOR <= ratio <= ERROR_FACTOR):
        what = "one-sided 68.27 % width" if row.bound is not None else "posterior std"
        row.failures.append(f"irpol 1-sigma {sigma:.4g} vs {what} {width:.4g}: ratio {ratio:.3f} outside "
                            f"[1/{ERROR_FACTOR:g}, {ERROR_FACTOR:g}]")
    if not (interval[0] <= value <= interval[1]):
        what = "one-sided 95 %" if row.bound is not None else "central 95 %"
        row.failures.append(f"irpol estimate {value:.6g} outside the {what} interval "
                            f"[{interval[0]:.6g}, {interval[1]:.6g}]")
    return row


def print_table(results: list[Sampled]) -> None:
    print()
    print(f"{'material':<16}{'param':<7}{'irpol':>12}{'irpol 1-sig':>12}{'GN 1-sig':>11}{'post mean':>12}"
          f"{'post std':>11}{'ratio':>7}{'central 95 % interval':>27}{'tau':>6}  verdict")
    for r in results:
        for p in r.rows:
            iv = f"{p.irpol_value:.6g}" if p.irpol_value is not None else "-"
            isg = f"{p.irpol_sigma:.4g}" if p.irpol_sigma else "-"
            ratio = f"{p.irpol_sigma / p.std:.3f}" if p.irpol_sigma and p.std > 0 else "-"
            verdict = "-" if p.irpol_value is None else ("PASS" if not p.failures else "FAIL")
            interval = f"[{p.central95[0]:.6g}, {p.central95[1]:.6g}]"
            print(f"{r.name:<16}{p.name:<7}{iv:>12}{isg:>12}{p.gauss_newton_sigma:>11.4g}{p.mean:>12.6g}"
                  f"{p.std:>11.4g}{ratio:>7}{interval:>27}{p.tau:>6.1f}  {verdict}")
            if p.bound is not None:
                print(f"{'':<23}at bound {p.bound:g}: one-sided 68.27 % width {p.one_sided_width:.4g} "
                      f"(irpol/width {p.irpol_sigma / p.one_sided_width:.3f}), one-sided 95 % interval "
                      f"[{p.one_sided95[0]:.6g}, {p.one_sided95[1]:.6g}]")
    print()
    for r in results:
        irpol = f"irpol fit {r.irpol_seconds:.2f} s, " if r.irpol_seconds is not None else ""
        print(f"{r.name}: {r.distribution}, {r.walkers} walkers x {r.steps} steps (+ burn-in), acceptance "
              f"{r.acceptance:.2f}, {irpol}sampling {r.seconds:.1f} s")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--irpol", help="path to the irpol binary (default: $IRPOL, target dirs, PATH)")
    ap.add_argument("--file", nargs="+", default=[os.path.join(cc.REPO, "measurements", "paper_paint.csv")],
                    help="measurement CSV(s) (default: measurements/paper_paint.csv)")
    ap.add_argument("--walkers", type=int, default=40)
    ap.add_argument("--burn", type=int, default=800)
    ap.add_argument("--steps", type=int, default=3500, help="production steps per walker")
    ap.add_argument("--seed", type=int, default=20240611)
    ap.add_argument("--no-irpol", action="store_true", help="only sample (with --distribution), no comparison")
    ap.add_argument("--distribution", default="cauchy", choices=("cauchy", "gaussian"),
                    help="distribution sampled with --no-irpol")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    results: list[Sampled] = []
    try:
        irpol = None if args.no_irpol else cc.find_irpol(args.irpol)
        for path in args.file:
            r = sample(path, irpol, args.distribution, args.walkers, args.burn, args.steps, args.seed)
            bad = [(p.name, msg) for p in r.rows for msg in p.failures]
            print(f"{r.name}: {r.model_check}; " + ("sampled" if irpol is None else "FAIL" if bad else "PASS"),
                  flush=True)
            for name, msg in bad:
                print(f"  FAIL {r.name} {name}: {msg}")
            results.append(r)
    except cc.SetupError as e:
        print(f"setup error: {e}", file=sys.stderr)
        return 2
    print_table(results)
    print(f"\n(total {time.perf_counter() - t_start:.1f} s)")
    if args.no_irpol:
        print(f"0 passed, 0 failed ({len(results)} files sampled without irpol)")
        return 0
    failed = sum(1 for r in results if any(p.failures for p in r.rows))
    print(f"{len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
