"""Figures of suspsim results (object-oriented Matplotlib, no pyplot state, no file I/O)."""
