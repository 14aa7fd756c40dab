"""mpc lsp: the language server of model definitions and pipeline files (specs/lsp.md)."""
