"""Lark grammars of mpc, shipped as package data."""
