"""MCTS over task skeletons with reverse-search grounding, plans and the independent validator."""
