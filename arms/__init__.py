"""Arm files (TOML) shipped with om_redundant; see :mod:`om_redundant.arm` for the format."""
