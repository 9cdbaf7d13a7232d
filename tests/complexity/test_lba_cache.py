"""The LBA construction is cached on the automaton it describes, never keyed by ``id()``."""

import dataclasses
import gc
import weakref

import numpy as np

import csplab.complexity.lba as lba_mod
from csplab.complexity.lba import lba_problem, load_lba


def test_construction_is_built_once_per_automaton():
    M = load_lba("anbncn")
    _, c1 = lba_problem(M, "abc")
    _, c2 = lba_problem(M, "aabbcc")
    assert c1 is c2 is M.construction
    assert c1.lba is M


def test_a_fresh_automaton_gets_its_own_construction():
    M = load_lba("anbncn")
    M2 = dataclasses.replace(M, name="copy")
    assert M2.construction is not M.construction
    assert M2.construction.lba is M2
    assert np.array_equal(M2.construction.T, M.construction.T)


def test_no_module_level_cache_keeps_automata_alive():
    assert not hasattr(lba_mod, "_CACHE")
    M = load_lba("ww")
    lba_problem(M, "aa")
    ref = weakref.ref(M)
    del M
    gc.collect()
    assert ref() is None
