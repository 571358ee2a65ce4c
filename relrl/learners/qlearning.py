"""Q-learning with necessity (Algorithm 1, Eq. 3) over a numpy table."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from relrl.engine import Engine, one
from relrl.errors import PolicyError
from relrl.learners.base import DOMAINS, Learner, LearnerSpec, Parameter, StepOut
from relrl.learners.registry import register
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

    Parameters: alpha, gamma, epsilon, q_init. It chooses in Python (through the engine's
    ``external`` learner), so its parameters are declared here, not in Prolog.
    """

    name = "qlearning"
    python_spec = LearnerSpec(
        name=name, engine="external",
        parameters=(Parameter("alpha", 0.2, "unit"), Parameter("gamma", 0.9, "unit"),
                    Parameter("epsilon", 0.05, "unit"), Parameter("q_init", 30.0)),
        serves={DOMAINS: {}})

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
        """Load a table saved by :meth:`save`, checked as a whole before it replaces this
        one: the domain's responses (in order), one row per (state, necessity), each state a
        code of the domain's features and each necessity the domain's (or ``none``), every
        Q finite and no larger in magnitude than a policy's values may be
        (``relrl_policy:policy_max_number/1``). Array shapes are read from the file's
        headers before any array, so a table larger than the domain allows is refused
        without being read.

        Raises:
            PolicyError: not a relrl Q-table of this domain (names the file and what is
                wrong).
        """
        path = Path(path)
        engine = self._engine()
        mine = [format_term(r) for r in self.responses]
        necessities = [*engine.necessities, "none"]
        states = 1 << len(engine.kb.features())
        arrays = _read_table(path, max_rows=states * len(necessities), width=len(mine))
        q, codes, names = arrays["q"], arrays["codes"], arrays["necessities"]
        responses = [str(r) for r in arrays["responses"]]
        if responses != mine:
            raise PolicyError(f"{path}: learned for another domain: the table's responses "
                              f"{responses} are not the domain's {mine}")
        rows: dict[tuple[int, str], int] = {}
        for i, (code_text, necessity) in enumerate(zip(codes, names, strict=True)):
            code = _state_code(str(code_text))
            if code is None or not 0 <= code < states:
                raise PolicyError(f"{path}: row {i}: state {str(code_text)[:40]!r} is not a "
                                  f"state code of this domain (0 to 2^{states.bit_length() - 1}"
                                  " - 1)")
            if str(necessity) not in necessities:
                raise PolicyError(f"{path}: row {i}: {str(necessity)[:40]!r} is not a necessity "
                                  f"of this domain ({', '.join(necessities)})")
            key = (code, str(necessity))
            if key in rows:
                raise PolicyError(f"{path}: rows {rows[key]} and {i} are both state {code} "
                                  f"under {necessity}")
            rows[key] = i
        values = np.asarray(q, dtype=float)
        bound = float(one(engine.kb, "policy_max_number"))
        bad = np.flatnonzero(~(np.abs(values) <= bound).all(axis=1))
        if len(bad):
            i = int(bad[0])
            j = int(np.flatnonzero(~(np.abs(values[i]) <= bound))[0])
            raise PolicyError(f"{path}: row {i}: the Q of {mine[j]} is {float(values[i, j])!r}: a "
                              f"policy's values are finite numbers of magnitude at most "
                              f"{bound:g}")
        self._rows = rows
        self._q = values if len(values) else np.full((64, len(mine)), self.params["q_init"])
        self._prev = None


#: the arrays of a saved Q-table and the kinds of values they may hold (numpy dtype kinds).
_TABLE = {"q": "fiu", "codes": "Uiu", "necessities": "U", "responses": "U"}
#: the longest text a code, necessity or response of a table may be (characters).
_MAX_TEXT = 1024


def _state_code(text: str) -> int | None:
    """A state code written as decimal digits (None for anything else)."""
    return int(text) if text.isascii() and text.isdigit() and len(text) <= 4096 else None


def _read_table(path: Path, *, max_rows: int, width: int) -> dict[str, np.ndarray]:
    """The arrays of the Q-table at ``path``, their shapes and kinds checked from the
    headers first (at most ``max_rows`` rows of ``width`` responses).

    Raises:
        PolicyError: not a .npz of the four arrays of a Q-table, or larger than allowed.
    """
    import zipfile

    def bad(why: str) -> PolicyError:
        return PolicyError(f"{path}: not a relrl Q-table (.npz): {why}")

    try:
        with zipfile.ZipFile(path) as archive:
            shapes = {}
            for name in _TABLE:
                try:
                    member = archive.open(f"{name}.npy")
                except KeyError:
                    raise bad(f"no array {name!r}") from None
                with member:
                    version = np.lib.format.read_magic(member)
                    read = np.lib.format.read_array_header_1_0 if version == (1, 0) \
                        else np.lib.format.read_array_header_2_0
                    shape, _, dtype = read(member)
                if dtype.kind not in _TABLE[name] or (dtype.kind == "U"
                                                      and dtype.itemsize > 4 * _MAX_TEXT):
                    raise bad(f"array {name!r} holds {dtype}")
                shapes[name] = shape
            rows = shapes["q"][0] if len(shapes["q"]) == 2 else -1
            if shapes["q"] != (rows, width) or shapes["codes"] != (rows,) \
                    or shapes["necessities"] != (rows,) or shapes["responses"] != (width,):
                if len(shapes["responses"]) == 1 and shapes["responses"] != (width,):
                    raise PolicyError(f"{path}: learned for another domain: the table has "
                                      f"{shapes['responses'][0]} responses, the domain "
                                      f"{width}")
                raise bad(f"inconsistent arrays {shapes}")
            if rows > max_rows:
                raise bad(f"{rows} rows, more than the domain's {max_rows} (state, "
                          "necessity) pairs")
        with np.load(path, allow_pickle=False) as data:
            return {name: data[name] for name in _TABLE}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise bad(str(exc)) from None
