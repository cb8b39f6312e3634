"""Colour constants."""
import numpy as np

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
"""Rec. 709 luminance weights of linear RGB, as Blender's default colour management (and Cycles) use."""
