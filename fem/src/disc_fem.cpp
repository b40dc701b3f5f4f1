// placeholder, replaced by the FEM implementation
