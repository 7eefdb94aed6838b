"""Gear trains: the planetary tooth-number synthesis of [Kavetsky & Geresh] and the
atlas of epicyclic gear trains.

One module per topic: ``planetary`` (the 2AA double-satellite scheme: tooth numbers
Z1..Z4 for a required ratio, and the admissible ratio range); ``atlas`` (one-DOF
epicyclic gear trains: rotation and displacement graphs).
"""
