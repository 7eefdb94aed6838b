"""Dimensional synthesis: from a structure to a dimensioned, working mechanism.

This plug-in owns the design side of the toolkit: the matrix synthesis of
hinged four-bars and the path, function and motion synthesis of one-DOF linkages,
over one topology or over an atlas of chains.  ``mjstruct.synthesis`` beside it is
*structural* synthesis (cells, atlases, catalog look-up): which chains exist.  This
package chooses the dimensions of a chain so that it does a job.

Layering: it builds on the kinematic model and its batched evaluation, the singular
analysis (``mjstruct.kinematics``) and the structural atlases (``mjstruct.synthesis``);
only the command line and the drawings sit above it (the layer contract in
``pyproject.toml``).
"""
