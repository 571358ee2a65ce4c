:- module(relrl_external, []).
:- use_module(engine).

/** <module> A learner outside Prolog

The `external` learner is the engine's side of a learner that keeps its numbers in Python
(Q-learning over a numpy table): the control step still runs in Prolog and reports the
state, the necessity, the reward and the allowed responses; Python chooses.
*/

relrl_engine:learner(external).
relrl_engine:learner_property(external, external).
relrl_engine:learner_init(external, _KB, _Params).
relrl_engine:learner_forget(external, _KB).
relrl_engine:learner_update(external, _KB, _Transition).
relrl_engine:learner_explain(external, _KB, _State, _N, external).
