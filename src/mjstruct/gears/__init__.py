"""Gear trains: the planetary tooth-number synthesis of [Kavetsky & Geresh].

One module per topic: ``planetary`` (the 2AA double-satellite scheme: tooth numbers
Z1..Z4 for a required ratio, and the admissible ratio range).
"""
