"""The papers' mechanisms as data on the general model (:class:`mechbal.Mechanism`).

Each module builds, from the parameters a case runner reads, the mechanism the paper describes:
joints with their parents and placements, every link's bodies, gear couplings and, for the closed
linkages, loop closures between named frames with the actuated joints named. The papers' closed
forms stay as fast paths and are tested against these general models
(tests/python/test_papers_loops.py).

* :mod:`mechbal.papers.five_bar`: the parallelogram 5R of the discs case (Coutinho & Hess Coelho).
* :mod:`mechbal.papers.paminsa`: PAMINSA (Briot & Arakelian 2009): pantograph legs, guides,
  columns, platform, counterweights, vertical counter-mass and wrist.
"""
