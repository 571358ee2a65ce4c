"""Q-learning with necessity (Algorithm 1, Eq. 3) over a numpy table."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from relrl.engine import Engine
from relrl.errors import PolicyError
from relrl.learners.base import Learner, StepOut, register
from relrl.outdir import write_atomic
from relrl.terms import Term, format_term

__all__ = ["QLearner"]


@register
class QLearner(Learner):
    """Tabular Q-learning whose rows are (state code, active necessity) pairs.

    Rows are added the first time a (state, necessity) pair is met (Algorithm 1: "if not
    have n_i defined then insert n_i on Q-table"); columns are the domain's responses in
    declaration order. Choice is epsilon-greedy over the allowed responses, ties broken at
    random; without exploration (evaluation) greedy.

    Parameters: alpha, gamma, epsilon, q_init.
    """

    name = "qlearning"
    engine_name = "external"
    defaults = {"alpha": 0.2, "gamma": 0.9, "epsilon": 0.05, "q_init": 30.0}

    def attach(self, engine: Engine, seed: int | None) -> None:
        """Start learning with ``engine`` (an empty table)."""
        super().attach(engine, seed)
        self._rows: dict[tuple[int, str], int] = {}
        self._q = np.full((64, len(self.responses)), self.params["q_init"])
        self._prev: tuple[int, int] | None = None

    def _row(self, code: int, necessity: str) -> int:
        key = (code, necessity)
        row = self._rows.get(key)
        if row is None:
            row = len(self._rows)
            if row == len(self._q):
                grown = np.full((2 * len(self._q), self._q.shape[1]), self.params["q_init"])
                grown[:row] = self._q
                self._q = grown
            self._rows[key] = row
        return row

    def act(self, out: StepOut, learning: bool, explore: bool | None = None) -> Term | None:
        """Update Q for the previous step (Eq. 3), then choose epsilon-greedily.

        Without learning, a state never met gets no row (every Q is q_init): evaluating
        leaves the table as it was."""
        if learning:
            row = self._row(out.code, out.necessity)
        else:
            row = self._rows.get((out.code, out.necessity), -1)
        allowed = out.allowed_index
        q = self._q
        if learning and self._prev is not None and allowed:
            prev_row, prev_action = self._prev
            target = out.reward + self.params["gamma"] * q[row, allowed].max()  # row >= 0
            q[prev_row, prev_action] += self.params["alpha"] * (target - q[prev_row, prev_action])
        if not allowed:
            self._prev = None
            return None
        if explore is None:
            explore = learning
        epsilon = self.params["epsilon"] if explore else 0.0
        if epsilon > 0 and self.rng.random() < epsilon:
            choice = allowed[int(self.rng.integers(len(allowed)))]
        else:
            values = q[row, allowed] if row >= 0 else np.full(len(allowed),
                                                              self.params["q_init"])
            best = np.flatnonzero(values == values.max())
            choice = allowed[int(best[self.rng.integers(len(best))])] if len(best) > 1 \
                else allowed[int(best[0])]
        self._prev = (row, choice) if learning else None
        return self.responses[choice]

    def end_episode(self) -> None:
        """No update links the next step to the last one."""
        self._prev = None

    def episode_state(self) -> Any:
        """The random stream and the last step (an evaluation must not disturb them)."""
        return (super().episode_state(), self._prev)

    def set_episode_state(self, state: Any) -> None:
        """Put back what :meth:`episode_state` saved."""
        rng_state, self._prev = state
        super().set_episode_state(rng_state)

    def size(self) -> dict[str, int]:
        """rows x actions positions, and the distinct states met."""
        rows = len(self._rows)
        return {"rows": rows, "actions": len(self.responses),
                "states": len({code for code, _ in self._rows}),
                "positions": rows * len(self.responses)}

    def _explain_from(self, detail: Term, state: Term, necessity: str) -> dict[str, Any]:
        """The Q row of the state the engine reports."""
        row = self._rows.get((state, necessity))
        if row is None:
            return {"ranked": [], "note": "state never met: every Q is q_init"}
        values = self._q[row]
        order = np.argsort(-values, kind="stable")
        return {"ranked": [{"response": format_term(self.responses[i]), "q": float(values[i])}
                           for i in order]}

    def save(self, path: str | Path, header: str = "") -> Path:
        """Write the table as .npz (atomic: temp file + rename)."""
        path = Path(path)
        keys = sorted(self._rows, key=self._rows.get)  # type: ignore[arg-type]
        rows = [self._rows[k] for k in keys]
        buf = io.BytesIO()
        np.savez(buf, q=self._q[rows], codes=np.array([str(k[0]) for k in keys]),
                 necessities=np.array([k[1] for k in keys]),
                 responses=np.array([format_term(r) for r in self.responses]),
                 header=np.array(header or "relrl policy: qlearning"))
        return write_atomic(path, buf.getvalue())  # temp file + rename, mode 0644

    def load(self, path: str | Path) -> None:
        """Load a table saved by :meth:`save` (its responses must match the domain's)."""
        import zipfile

        try:
            data = np.load(path, allow_pickle=False)
            fields = {k: data[k] for k in ("q", "codes", "necessities", "responses")}
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
            raise PolicyError(f"{path}: not a relrl Q-table (.npz): {exc}") from None
        if not (fields["q"].ndim == 2 and np.issubdtype(fields["q"].dtype, np.number)
                and len(fields["q"]) == len(fields["codes"]) == len(fields["necessities"])):
            raise PolicyError(f"{path}: not a relrl Q-table (.npz): inconsistent arrays")
        data = fields
        responses = [str(r) for r in data["responses"]]
        mine = [format_term(r) for r in self.responses]
        if responses != mine or fields["q"].shape[1] != len(mine):
            raise PolicyError(f"{path}: learned for another domain: the table's responses "
                              f"{responses} are not the domain's {mine}")
        try:
            self._rows = {(int(c), str(n)): i for i, (c, n) in
                          enumerate(zip(data["codes"], data["necessities"], strict=True))}
        except ValueError as exc:
            raise PolicyError(f"{path}: not a relrl Q-table (.npz): {exc}") from None
        self._q = np.array(data["q"], dtype=float)
        if len(self._q) == 0:
            self._q = np.full((64, len(self.responses)), self.params["q_init"])
        self._prev = None
