"""Exchange with other tools: pyslvs mechanism expressions, GraphML and node-link JSON.

Each format lives in its own module (:mod:`~mjstruct.exchange.pyslvs`,
:mod:`~mjstruct.exchange.graph_formats`); :mod:`~mjstruct.exchange.formats` picks one
by file suffix and reads or writes whole files.
"""
