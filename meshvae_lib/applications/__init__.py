"""The applications layer: generation, interpolation, embedding and exploration with a fitted mesh VAE (Sec. 4.5, 5)."""
