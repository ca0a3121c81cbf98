"""The sim-to-real gap on crest logs: logs to recordings, the model-plant log generator, the blind benchmark."""
