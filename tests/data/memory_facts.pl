/*  Facts the state plan reads straight off working memory (memory facts) and facts it runs
    as goals, side by side (tests/prolog/test_core.plt, step_parts).  */

stimulus(s).
stimulus(t).

fact(plain).                        % memory facts
fact(young).
fact(seen).
fact(placed(s)).
fact(placed(t)).
fact(near(_)).                      % declared open: any near(X)
fact(two).                          % goals
fact(dyn).
fact(both).
fact(qualified).
fact(open).
fact(older).

plain :- percept(see(s)).
young :- memory(hear(s), 0).
seen :- see(s).
placed(S) :- at(S, left).
near(left) :- see(t).
two :- percept(a).
two :- percept(b).
:- dynamic dyn/0.
dyn :- percept(a).
both :- percept(a), percept(b).
qualified :- relrl:percept(a).
open :- percept(pose(s, _)).
older :- memory(hear(s), 1).

memory_span(2).
