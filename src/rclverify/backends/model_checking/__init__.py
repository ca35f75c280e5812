"""Program model checking of Gwendolen agents with SPIN.

Two stages, as AJPF does when it exports to SPIN (Dennis, Fisher, Webster,
"Two-stage agent program verification"): stage one explores the agent
program under a verification environment into a finite :class:`StateGraph`
(:mod:`.graph`); stage two hands that graph and each LTL property to SPIN.
"""
