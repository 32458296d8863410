"""The comparison harness: how far each backend and each hardware constraint is from the golden
model, in spikes, in run time and in classification accuracy."""
