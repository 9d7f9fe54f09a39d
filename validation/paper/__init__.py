"""Reproduction scripts of the paper's figures (issue 4): each writes figures and a claims table."""
