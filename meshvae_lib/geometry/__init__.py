"""The geometry layer: meshes, deformation gradients, RIMD features and their reconstruction (no learning)."""
