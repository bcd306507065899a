"""The product's entry points: the ``hlvs`` command (:mod:`hlvs.cli`) and the submission service
as it is served, with the pages and the environment API mounted (:mod:`hlvs.app`).

This is the only package that wires the others together; nothing imports it.
"""

__all__: list[str] = []  # the entry points; no package imports hlvs
