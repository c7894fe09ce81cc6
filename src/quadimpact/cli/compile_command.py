"""``quadimpact compile``: the compiled loops into Numba's disk cache, ahead of their first use."""

from __future__ import annotations

import time
from collections.abc import Callable

import click

__all__ = ["compile_command"]


def _simulator() -> None:
    """A short run of each kind, through the sweeps' path and ``simulate``'s (tables too)."""
    from quadimpact import ImpactTrial, WallApproach, simulate
    from quadimpact.sweep.worker import warm_up

    warm_up()
    simulate(WallApproach(final_time_s=0.6))
    simulate(ImpactTrial(final_time_s=0.05))


def _environments() -> None:
    """One environment reset and stepped once (the batched one runs the same loop)."""
    from quadimpact.envs.single import ImpactRecoveryEnv

    env = ImpactRecoveryEnv()
    env.reset(seed=0)
    env.step(env.action_space.sample())
    env.close()


def _has_gymnasium() -> bool:
    import importlib.util

    return importlib.util.find_spec("gymnasium") is not None


@click.command("compile")
@click.option(
    "--no-environments",
    is_flag=True,
    help="Only the simulator, not the learning environments' loop.",
)
def compile_command(no_environments: bool) -> None:
    """Compile the simulator (and the learning environments) into Numba's disk cache.

    The first use of the simulator on a machine, or after its compiled
    sources changed, compiles its loop (about 180 s of CPU on a 2-core
    machine; the learning environments' own loop about 35 s more); Numba
    keeps the result in its disk cache (beside the sources, or in
    $NUMBA_CACHE_DIR), from which every later process loads it in about a
    second. This command does it now: in a container build, before a
    notebook session, or on each machine of a cluster. What is in the cache
    already is loaded, not compiled again. The learning environments need
    the rl extra (pip install 'quadimpact[rl]'); without it they are skipped.

    Prints, for each part, whether it was compiled or found in the cache, and
    the time it took.
    """
    from quadimpact.core import COMPILED_PARTS, announce_compilation, cache_is_warm

    parts: list[tuple[str, Callable[[], None]]] = [("simulator", _simulator)]
    if not no_environments:
        if _has_gymnasium():
            parts.append(("environments", _environments))
        else:
            click.echo(f"{'environments':<14}skipped (they need pip install 'quadimpact[rl]')")
    for part, warm_it in parts:
        entries, _what, seconds = COMPILED_PARTS[part]
        cached = cache_is_warm(*entries)
        if not cached:  # said here, in this command's words (and not again by the runs)
            announce_compilation(
                part,
                say=lambda _notice, part=part, seconds=seconds: click.echo(
                    f"quadimpact: compiling the {part} (about {seconds} s of CPU on a 2-core "
                    "machine) ...",
                    err=True,
                ),
            )
        wall, cpu = time.perf_counter(), time.process_time()
        warm_it()
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        how = "loaded from the cache" if cached else "compiled into the cache"
        if not cache_is_warm(*entries):
            how = "compiled, but Numba could not write its cache (see NUMBA_CACHE_DIR)"
        click.echo(f"{part:<14}{how} in {wall:.1f} s ({cpu:.1f} s of CPU)")
