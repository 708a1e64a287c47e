"""Runners of external solvers (MYSTRAN, CalculiX) on decks written by deckbridge."""
