from __future__ import annotations
ComLawResult = None
def com_law(*a, **k): raise NotImplementedError
