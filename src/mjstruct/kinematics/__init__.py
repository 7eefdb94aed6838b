"""Kinematics plug-in: triangle-rule position analysis, analogs, branches, singularities."""
