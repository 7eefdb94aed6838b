"""Drawings, animations and charts (matplotlib, imported only by the functions that draw).

Modules: ``layers`` (what a drawing can show and what each layer needs computed),
``scene`` (a solved motion and what its drawing needs), ``scheme``, ``vectors`` and
``annotations`` (the artists per layer), ``layout`` (limits, footer, figure shape),
``style`` (sizes, colours), ``placement`` (where labels go), ``drawing`` (one frame of
a scene, written), ``forces`` (loads, inertia and reactions layers, with the dynamics
plug-in), ``animation`` (GIF, HTML, MP4), ``charts`` (the chart registry: quantities
against q), ``atlas_sheet`` (crossing-free layouts of chains, atlas sheets),
``notebook`` (Jupyter pictures and tables), ``files`` (suffix checks, atomic writing),
``assur`` (the Assur decomposition on the link–joint graph), ``ms_diagram`` (the
four-bar P2–P3 diagram, singularity plug-in).
"""
