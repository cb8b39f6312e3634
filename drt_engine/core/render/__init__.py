"""A render from a prepared scene: progressive rounds, adaptive sampling, stop rules, reports
and merging parts."""
