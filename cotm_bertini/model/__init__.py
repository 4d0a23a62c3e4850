"""The model: kinematics, the equilibrium equations (sympy) and their compiled numeric forms."""
