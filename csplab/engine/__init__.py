"""The engine layer: the algorithms solvers and analyses share, below ``csplab.solvers``.

=====================================  ==============================================
module                                 what
=====================================  ==============================================
:mod:`csplab.engine.alg31`             Merrell's Alg. 3.1 as one compiled run
                                       (:func:`run_alg31`), the order vocabulary
                                       (:func:`scan_order`, :func:`check_order`)
:mod:`csplab.engine.sat`               the incremental SAT oracle (:class:`SatOracle`)
:mod:`csplab.engine.completability`    one :class:`Completability` protocol (SAT or
                                       search), :func:`first_inconsistent_prefix`,
                                       :func:`catalog_at` (C(p), C*(p)),
                                       :func:`search_solutions`, drawing labels from C*
:mod:`csplab.engine.pool`             worker processes (:class:`Workers`: a local
                                       process pool whose workers exit with their
                                       parent, or a Dask cluster) for the waves of
                                       modify-in-blocks and the experiments' sweeps
=====================================  ==============================================

The arc-consistency engine (:mod:`csplab.catalog`, compiled kernels in
:mod:`csplab._kernels`) and the CNF encodings (:mod:`csplab.cnf`) sit below it in the core.
Solvers (:mod:`csplab.solvers`) are thin adapters over these modules; nothing here imports a
solver. Submodules are imported explicitly (``from csplab.engine.sat import SatOracle``), so
importing the package costs nothing.
"""
