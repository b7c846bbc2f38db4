"""symlearn: learn planning symbols from robot interaction (Attentive DeepSym) and export them."""
__version__ = "0.1.0"
