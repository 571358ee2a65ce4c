:- module(relrl_learners, []).

/** <module> The learners the engine knows

Each learner is a module that adds clauses to the engine's hooks (engine.pl). Loading it
here is all it takes to make a learner available by name.
*/

:- use_module(etg).
:- use_module(contingency).
:- use_module(external).
:- use_module(tg).
:- use_module(ptg).
:- use_module(world_qtable).
