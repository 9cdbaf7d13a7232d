"""Random-number handling: every random callable takes ``rng`` and records its seed.

``rng`` may be an ``int`` seed, a :class:`numpy.random.Generator` or ``None`` (a fresh
seed is drawn from the operating system and recorded, so the run can be repeated).
numpy's global RNG is never used.

Examples
--------
>>> gen, seed = make_rng(7)
>>> seed
7
>>> int(gen.integers(100)) == int(make_rng(7)[0].integers(100))
True
"""

from __future__ import annotations

import secrets

import numpy as np

__all__ = ["RngLike", "make_rng"]

RngLike = int | np.random.Generator | None


def make_rng(rng: RngLike = None) -> tuple[np.random.Generator, int | None]:
    """Return ``(generator, seed)`` for an ``rng`` argument.

    Parameters
    ----------
    rng : int, numpy.random.Generator or None
        An integer seed, an existing generator (used as is, not copied), or ``None`` for a
        fresh seed drawn from the operating system.

    Returns
    -------
    generator : numpy.random.Generator
    seed : int or None
        The integer that reproduces the run with ``make_rng(seed)``. For a generator passed
        in, this is the entropy of its seed sequence when it was built from an int (its
        state may have advanced since), else ``None``.
    """
    if rng is None:
        seed = secrets.randbits(63)
        return np.random.default_rng(seed), seed
    if isinstance(rng, np.random.Generator):
        seq = getattr(rng.bit_generator, "seed_seq", None)
        entropy = getattr(seq, "entropy", None)
        return rng, int(entropy) if isinstance(entropy, int) else None
    if isinstance(rng, bool) or not isinstance(rng, int | np.integer):
        from csplab.errors import InputError

        raise InputError(f"rng must be an int seed, a numpy Generator or None, not {rng!r}")
    if int(rng) < 0:
        from csplab.errors import InputError

        raise InputError(f"rng seed must be non-negative, got {rng}")
    return np.random.default_rng(int(rng)), int(rng)
