"""What every layer shares and that imports nothing else of DRT: the kernel decorator, vectors
and frames, warps, colour and numeric constants."""
