"""The model layer: what trains and runs the mesh VAE (see docs/ARCHITECTURE.md)."""
