"""Builders: the validated scenario (:mod:`ptztrack.config`) turned into the objects the loop runs.

Below the builders no module sees the configuration models; the maths takes
plain parameters.
"""
