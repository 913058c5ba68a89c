"""Everything SymPy: the model's formulas derived, the papers' formulas printed, and the code.

* :mod:`~stringstab.derive.symbolic` — Γ(s) (IDL eq 11), Ψ1–Ψ3 and Λ derived from the
  vehicle model and the eq-4 law, and the margin g(ω) behind Proposition 1;
* :mod:`~stringstab.derive.sampled_symbolic` — the same loop under a zero-order hold;
* :mod:`~stringstab.derive.reaction` — the loop with a reaction delay θ_r on the whole command
  (issue 25): Γ(s) with its quasi-polynomial denominator, g_θ(ω), Ψ with θ_r, and what the
  Taylor route would test (its code blocks: :mod:`~stringstab.derive.codegen_reaction`);
* :mod:`~stringstab.derive.printed` — the formulas as the papers print them (reference only);
* :mod:`~stringstab.derive.errata` — where the printed and the derived formulas differ, and
  how much it matters;
* :mod:`~stringstab.derive.derivation` — the derivation written out step by step;
* :mod:`~stringstab.derive.codegen` — writes :mod:`~stringstab.derive.generated`, the numeric
  code of every derived formula (plain arithmetic, no SymPy at run time), which the
  certificates in :mod:`stringstab.certify` evaluate.

Importing this package loads nothing; its modules load SymPy when imported (except
:mod:`~stringstab.derive.generated`, which needs NumPy only).
"""
