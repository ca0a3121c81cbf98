"""Importers of outside data into crest experiment logs."""
