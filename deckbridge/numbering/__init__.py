"""Deck numbering: node, element and gap ids of every deck family, pure functions of mesh and model.

One place for the id facts that renderers write and readers map back (readers never import
:mod:`deckbridge.render`):

- :mod:`.skirt`: skirt node and element ids, common to every deck (mesh index + 1);
- :mod:`.nastran`: the Nastran family (penalty ``.bdf`` and MYSTRAN linear ``.bdf``): offsets, reference
  node, grounded gap nodes and contact element ids (:func:`.nastran.gap_layout`);
- :mod:`.inp`: the inp family (Abaqus and CalculiX): reference node, fixed master rings, spring ids
  (:func:`.inp.layout`); what only CalculiX numbers (GAPUNI gaps, node-to-surface groups) is in its
  folder, :mod:`deckbridge.dialects.calculix.numbering`.

A numbering shared by several dialects lives here; one that a single dialect uses lives in its folder.
"""
