"""Singular positions plug-in: where a one-DOF linkage's input or output stops, where
its branches cross, and the clearance zones around those positions.

Built on the kinematics (its geometry, tolerances and Jacobians), below the
dimensional synthesis that selects designs by their singular positions.  Modules:
``analysis`` (:func:`~mjstruct.singular.analysis.singular_analysis`, the entry; CLI:
``mjstruct singular``), ``curve`` (the closure equations and the configuration curve
traced through change points), ``fourbar`` (the four-bar singularity matrix and its
closed-form theory) and ``clearance`` (zones from joint clearances).  A new classifier
of singular positions goes in a module of its own here.  Nothing is imported here, so
the kinematics stays light.
"""
