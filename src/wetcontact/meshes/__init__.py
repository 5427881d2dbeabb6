"""gmsh mesh builders (one function per geometry) and meshio I/O."""
