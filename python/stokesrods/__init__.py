"""stokesrods: elastic rods (Discrete Elastic Rods) in a viscous Stokes fluid, from Python.

    import stokesrods
    result = stokesrods.run("case.toml", overrides={"rods.omega_bar": 533})
    result.timeseries["delta_b"]          # NumPy arrays keyed by the timeseries.csv columns
    result.summary["final"]               # summary.json as a dict
    sim = stokesrods.Simulation("case.toml")
    sim.step(100); sim.time; sim.positions(1)

Everything runs in the C++ core (the compiled module stokesrods._core): the same reader and
validation as the command line (bad input raises ValueError with its message), the same solver,
the same output files. The reading and drawing modules (results, render, plot) need only NumPy
and Matplotlib, so `python3 -m stokesrods.render` works without the compiled module.
"""
import json
import os
import sys
import time as _time

from .results import Result, load

__all__ = ["run", "load", "Result", "Simulation", "SimulationFailed", "resolve_config"]


class SimulationFailed(RuntimeError):
    """A run that stopped on a numerical failure; `result` holds what it wrote."""

    def __init__(self, message, result):
        super().__init__(message)
        self.result = result


def __getattr__(name):
    # The compiled parts, imported on first use (PEP 562).
    if name in ("Simulation", "resolve_config", "__version__"):
        from . import _core
        return getattr(_core, name)
    raise AttributeError(f"module 'stokesrods' has no attribute {name!r}")


def _progress_printer():
    tty = sys.stderr.isatty()
    last = [-1e9]

    def show(t, duration, wall, steps):
        fraction = t / duration if duration > 0 else 1.0
        speed = t / wall if wall > 0 else 0.0
        left = (duration - t) / speed if speed > 0 else 0.0
        line = (f"t = {t:.4g} s of {duration:.4g} s ({100 * fraction:5.1f}%), "
                f"{speed:.3g} sim s per wall s, {_time.strftime('%H:%M:%S', _time.gmtime(left))} left")
        if tty:
            sys.stderr.write("\r" + line + "   " + ("\n" if fraction >= 1.0 else ""))
        elif wall - last[0] >= 10.0 or fraction >= 1.0:
            last[0] = wall
            sys.stderr.write("[stokesrods] " + line + "\n")
        sys.stderr.flush()
    return show


def run(config, overrides=None, progress=False, output=None, resume=False, check=True):
    """Runs one case as `stokesrods run` does and returns its Result.

    config: a TOML path or a dict of the same schema. overrides: {"rods.omega_bar": 533} or
    ["rods.omega_bar=533", ...] (the command line's --set). progress: True to print progress
    on stderr, or a function (time, duration, wall_seconds, steps). output: the output directory
    (the command line's --output). check: raise SimulationFailed on a numerical failure (else the
    Result has status "failed"). Ctrl-C stops the run (outputs flushed, checkpoint written) and
    raises KeyboardInterrupt. Bad input raises ValueError, an unwritable output OSError.
    """
    from . import _core
    if output is not None:
        overrides = _with_output(overrides, os.fspath(output))
    callback = _progress_printer() if progress is True else (progress or None)
    status = _core.run(config, overrides, callback, resume)
    result = load(status["output_dir"])
    if check and status["status"] == "failed":
        raise SimulationFailed(f"numerical failure: {status['message']}", result)
    return result


def _with_output(overrides, output):
    if overrides is None:
        return {"run.output": output}
    if isinstance(overrides, dict):
        return {**overrides, "run.output": output}
    return list(overrides) + ["run.output=" + json.dumps(output)]
