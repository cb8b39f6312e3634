"""Where rays meet the scene: Embree scenes, motion, the camera's rays."""
