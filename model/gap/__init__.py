"""Sim-to-real gap diagnosis: calibration, where the gap lies, which unmodelled effect explains it.

Works on arrays (`Recording`), never on files; crest turns logs into recordings.
"""
