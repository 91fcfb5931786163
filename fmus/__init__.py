"""FMI 2.0 co-simulation wrappers of the components, and the build that packs them."""
