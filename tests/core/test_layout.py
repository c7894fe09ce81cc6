"""The layout of the compiled core's arrays is a checked contract (``core/layout.py``).

Every slot of every array is declared in a ``Block`` (the core's records,
the controllers' parameter and memory blocks, the learning environment's
blocks): no two slots overlap, every size covers its slots, every constant of
a block's prefix is one of its declared slots, and the records' factories
allocate the declared sizes.
"""

from __future__ import annotations

import importlib
from collections import defaultdict

import numpy as np
import pytest

from quadimpact.core import controller_slots as CTL
from quadimpact.core import estimator_slots as ESL
from quadimpact.core import feature_slots as FS
from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.core import vehicle_slots as VS
from quadimpact.core.contact_slots import NCS
from quadimpact.core.geometry import NPAIR
from quadimpact.core.recording_slots import NEP, NOUT, out_width
from quadimpact.core.records import new_data, new_output, new_work
from quadimpact.core.rotors import NRIN
from quadimpact.core.sensors import imu_slots as IMS
from quadimpact.core.sensors import measurement_slots as MSS

# every module that declares blocks (importing them registers their blocks)
DECLARING = (
    "quadimpact.core.layout",
    "quadimpact.core.contact_slots",
    "quadimpact.core.recording_slots",
    "quadimpact.core.excursion_slots",
    "quadimpact.core.hover_slots",
    "quadimpact.core.interval_slots",
    "quadimpact.core.feature_slots",
    "quadimpact.core.shape_slots",
    "quadimpact.core.controller_slots",
    "quadimpact.core.estimator_slots",
    "quadimpact.core.vehicle_slots",
    "quadimpact.core.sensors.imu_slots",
    "quadimpact.core.sensors.measurement_slots",
    "quadimpact.core.approach",
    "quadimpact.core.impacts",
    "quadimpact.core.rotors",
    "quadimpact.core.geometry",
    "quadimpact.core.controllers.common",
    "quadimpact.core.controllers.recovery",
    "quadimpact.core.controllers.residual",
    "quadimpact.core.estimators.complementary",
    "quadimpact.core.estimators.ekf",
    "quadimpact.core.estimators.ekf_additive",
    "quadimpact.core.estimators.nav_ekf",
    "quadimpact.core.sensors.detection",
    "quadimpact.core.envs.episode_layout",
)
# constants that carry a block's prefix without being one of its slots
NOT_SLOTS = {"OUT_DELTA"}  # the first per-feature column: the end of the fixed columns


def _blocks() -> list[L.Block]:
    for name in DECLARING:
        importlib.import_module(name)
    return list(L.Block.registry.values())


def test_every_array_of_the_records_and_the_environment_is_declared():
    arrays = {b.array for b in _blocks()}
    expected = {
        "x", "veh", "feat", "shapes", "pairs", "opts", "ctrl", "scfg", "span",  # Model
        "ls", "cs", "rin", "meas", "sst", "mem",  # Data
        "imu", "out", "episodes", "stats",  # Output
        "ctrl.params",  # the controllers' parameter blocks
        "env.state", "env.par",  # the learning environment
    }  # fmt: skip
    assert expected <= arrays, sorted(expected - arrays)


def test_no_two_slots_overlap_and_every_size_covers_its_slots():
    by_array: dict[str, list[tuple[int, int, str]]] = defaultdict(list)
    for b in _blocks():
        for name, (offset, width) in b.slots.items():
            assert offset >= b.start and width >= 1
            if b.capacity is not None:
                assert offset + width <= b.capacity, name
            by_array[b.array].append((offset, offset + width, name))
    assert by_array
    for array, spans in by_array.items():
        spans.sort()
        for (a0, a1, an), (b0, _, bn) in zip(spans, spans[1:], strict=False):
            assert a1 <= b0, f"{array}: {an} [{a0}, {a1}) overlaps {bn} at {b0}"


def test_declared_offsets_are_the_module_constants_and_nothing_escapes_a_block():
    blocks = _blocks()
    declared_anywhere = defaultdict(set)  # a name two alternatives declare has two offsets
    for b in blocks:
        for n, (o, _) in b.slots.items():
            declared_anywhere[n].add(o)
    for modname in DECLARING:
        module = importlib.import_module(modname)
        mine = [b for b in blocks if b.module == modname and b.slots]
        for b in mine:
            for name, (offset, _) in b.slots.items():
                assert getattr(module, name) == offset, f"{modname}.{name}"
            if b.size_name and hasattr(module, b.size_name):
                assert getattr(module, b.size_name) == b.next, f"{modname}.{b.size_name}"
        prefixes = {b.prefix for b in mine}
        for name, value in vars(module).items():
            if not isinstance(value, int) or isinstance(value, bool) or name in NOT_SLOTS:
                continue
            if any(name.startswith(p) for p in prefixes):
                # a slot of a block declared here, or imported from the module declaring it
                assert value in declared_anywhere.get(name, ()), (
                    f"{modname}.{name} = {value} is not a slot of a declared block"
                )


def test_a_component_block_stays_inside_the_region_it_extends():
    """An estimator's or the detector's block lies inside the central region it extends
    (``ecfg[EC_OWN:]``, ``est[ES_OWN:]``, the detector's ``scfg``, ``sst`` and ``imu``
    regions): its capacity says so."""
    regions = {
        "ecfg.": (ESL.EC_OWN, ESL.EC_OWN + ESL.N_OWN_ECFG),
        "est.": (ESL.ES_OWN, ESL.ES_OWN + ESL.N_OWN_EST),
        "scfg.detector": (IMS.SC_DETECTOR, IMS.SC_DETECTOR + L.N_DETECTOR_CFG),
        "sst.detector": (IMS.SS_DETECTOR, IMS.SS_DETECTOR + 1),
        "imu.detector": (IMS.I_DETECTOR, IMS.I_DETECTOR + 1),
    }
    seen = set()
    for b in _blocks():
        for head, (lo, hi) in regions.items():
            if b.array.startswith(head) and b.slots:
                seen.add(head)
                assert b.capacity == hi, b.array
                for name, (offset, width) in b.slots.items():
                    assert lo <= offset and offset + width <= hi, name
    assert seen == set(regions)


def test_each_part_of_stats_fills_the_region_placed_for_it():
    """``layout.py`` places the excursion's, the hover tests' and the integrator's slots,
    declared by their owners, in ``stats`` at regions as wide as their declared sizes."""
    _blocks()
    regions = L.Block.registry["stats:ST_"].slots
    parts = {"ST_EXCURSION": "stats.excursion:EX_", "ST_HOVER": "stats.hover:HV_"}
    parts["ST_HELD"] = "stats.held:HH_"
    parts["ST_STEPS"] = "stats.steps:IS_"
    for region, key in parts.items():
        part = L.Block.registry[key]
        assert part.start == 0 and regions[region][1] == part.next, region


def test_the_factories_allocate_the_declared_sizes():
    m_feat, n_shapes, n_out = 3, 2, 5
    from quadimpact.core.records import model

    m = model(
        x0=np.zeros(L.NX), t0=0.0, tf=1.0, veh=np.zeros(VS.NVEH),
        feat=np.zeros((m_feat, FS.NFEAT)), shapes=np.zeros((n_shapes, SHP.NSHAPE)),
        pairs=np.zeros((m_feat * n_shapes, NPAIR), dtype=np.int64), opts=np.zeros(L.NOPT),
        ctrl=np.zeros(CTL.NCTRL), t_out=np.linspace(0.0, 1.0, n_out),
    )  # fmt: skip
    assert m.span.shape == (L.NSPAN,) and m.scfg.shape == (IMS.NSCFG,)
    d = new_data(m)
    assert [a.shape for a in d] == [
        (L.NX,), (L.NLS,), (m_feat * n_shapes, NCS), (NRIN,), (L.NMEM,), (ESL.NEST,), (MSS.NMEAS,),
        (IMS.NSST,),
    ]  # fmt: skip
    o = new_output(m, 7, 11)
    assert o.out.shape == (n_out, out_width(m_feat)) == (n_out, NOUT + 2 * m_feat)
    assert o.imu.shape == (7, IMS.NIMU) and o.episodes.shape == (11, NEP)
    assert o.stats.shape == (L.NSTAT,)
    w = new_work(4)
    assert w.K.shape == (7, L.NX) and w.ev_sig.shape == (4,)


def test_a_block_refuses_a_bad_declaration():
    b = L.Block("test.scratch", "T_", capacity=3)
    assert b.slot("T_A", 2) == 0
    with pytest.raises(ValueError, match="must start with"):
        b.slot("U_B")
    with pytest.raises(ValueError, match="twice"):
        b.slot("T_A")
    with pytest.raises(ValueError, match="overflows"):
        b.slot("T_C", 2)
    del L.Block.registry["test.scratch:T_"]


def test_kinds_are_integers_with_names():
    assert L.FEAT_RING == L.FeatureKind.RING and isinstance(L.FEAT_RING, int)
    assert L.SHAPE_PLANE == L.ShapeKind.PLANE and type(L.SHAPE_PLANE) is int
    assert L.Status(L.STATUS_FAILED).name == "FAILED"
    assert set(L.REASON_TEXT) == {int(r) for r in L.Reason}


def test_every_layout_name_the_code_reads_is_declared():
    """A slot that moved to its component's declaration module leaves no reader behind:
    every upper-case attribute of ``layout`` read through its alias (``as L``) and every name
    imported from ``quadimpact.core.layout`` in the package, the tests, the
    benchmarks and the examples exists in ``core/layout.py``."""
    import ast
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    dirs = ("src", "tests", "benchmarks", "examples")
    files = [p for d in dirs for p in (root / d).rglob("*.py")]
    missing = []
    for path in files:
        tree = ast.parse(path.read_text())
        aliases = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module == "quadimpact.core.layout":
                missing += [f"{path.name}: {a.name}" for a in node.names if not hasattr(L, a.name)]
            elif isinstance(node, ast.ImportFrom) and node.module == "quadimpact.core":
                aliases |= {a.asname or a.name for a in node.names if a.name == "layout"}
        text = path.read_text()
        for alias in aliases:
            for name in re.findall(rf"(?<![\w.]){alias}\.([A-Z][A-Z0-9_]*)\b", text):
                if not hasattr(L, name):
                    missing.append(f"{path.name}: {alias}.{name}")
    assert len(files) > 100 and not missing, sorted(set(missing))
