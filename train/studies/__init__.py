"""The paper studies: its figures, the generalisation study and the demo; and manual play."""
