:- module(relrl_choice,
          [ ties/4,               % +Qs, +Actions, +Best, -Ties
            softmax_member/5      % +Qs, +Actions, +Best, +Tau, -Action
          ]).

/** <module> Choosing among valued actions (the learners that value each action: tg, qtable)

Qs and Actions are parallel lists; Best is the largest of Qs. Both draw from the calling
thread's random stream (the knowledge base's own, claimed by the engine for the step).
*/

%!  ties(+Qs, +Actions, +Best, -Ties) is det.
%
%   The actions whose value equals Best, in order.

ties([], [], _, []).
ties([Q|Qs], [A|As], Best, Ties) :-
    (   Q =:= Best
    ->  Ties = [A|Ties1]
    ;   Ties = Ties1
    ),
    ties(Qs, As, Best, Ties1).

%!  softmax_member(+Qs, +Actions, +Best, +Tau, -Action) is det.
%
%   An action drawn with probability proportional to exp((Q - Best) / Tau) (Boltzmann
%   exploration at temperature Tau; subtracting Best keeps exp/1 from overflowing).

softmax_member(Qs, Actions, Best, Tau, Action) :-
    weights(Qs, Best, Tau, Ws, 0.0, Total),
    X is random_float * Total,
    pick(Ws, Actions, X, Action).

weights([], _, _, [], T, T).
weights([Q|Qs], Best, Tau, [W|Ws], T0, T) :-
    W is exp((Q - Best) / Tau),
    T1 is T0 + W,
    weights(Qs, Best, Tau, Ws, T1, T).

pick([W|Ws], [A|As], X, Action) :-
    (   ( X < W ; Ws == [] )
    ->  Action = A
    ;   X1 is X - W,
        pick(Ws, As, X1, Action)
    ).
