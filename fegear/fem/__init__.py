"""Finite-element models of the elastic bodies (scikit-fem)."""

from fegear.fem.elasticity import ElasticBody, assemble_body, boundary_dofs

__all__ = ["ElasticBody", "assemble_body", "boundary_dofs"]
