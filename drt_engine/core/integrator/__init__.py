"""The paths of a wave: camera rays to last bounce, records between stages, the render plan,
the ratio estimator."""
