"""Import an analyst's solid mesh with named node sets (issue 15).

- :mod:`.raw`: :class:`~.raw.RawMesh` (user node/element ids, coordinates, elements by type, node
  sets) read from Abaqus/CalculiX ``.inp`` (:mod:`.inp_file`), Gmsh ``.msh`` (:mod:`.msh_file`, meshio)
  or Nastran ``.bdf`` (:mod:`.bdf_file`, pyNastran);
- :mod:`.checks`: the import checks, each a one-line ModelError naming the set and the node;
- :mod:`.general`: the imported mesh as a :class:`deckbridge.mesh.SkirtMesh` (slave sets, k_c,
  top weights, user ids), built by :func:`deckbridge.mesh.build_mesh` when ``mesh.file`` is set;
- :mod:`.spec`: the model keys ``mesh.file/sets/units/axis``; :mod:`.write`: a mesh file written back
  out (tests, ``deckbridge import``).
"""
