"""A part, by job: what a user says of it (`spec`: the part spec, its material's limits, the
length units a CAD file may be in), the built-in parametric models (`models`), the typed
collision shapes a part is made of (`primitives`: Box, Cylinder, Hull), reading a CAD file in
metres (`meshes`), the mass properties of a solid (`mass`), the convex pieces of a concave mesh
(`pieces`), and the geometry they make together (`geometry`: build_part, PartGeometry).

`spec`, `models` and `primitives` need only numpy: a package that only names a part (the
experiment file's schema, the messages' conversions) does not load the mesh stack (trimesh,
CoACD). Units: metres, kilograms; quaternions (x, y, z, w).
"""
