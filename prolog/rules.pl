:- module(relrl_rules,
          [ rule_holds/2,         % +KB, +Goal
            rules_mask/4,         % +KB, +GoalBits, +Mask0, -Mask
            rule_solution/2,      % +KB, +Goal
            rule_where/3          % +KB, +Goal, -Where
          ]).
:- use_module(library(error)).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

/** <module> Running the domain's goals

Every goal of a domain that the engine runs — a fact's definition, an ETG test, a constraint
rule, a behaviour rule's antecedent, a necessity input, a relation of the relational view —
runs through this module. A goal that fails is false. An exception is never turned into
failure: it propagates, wrapped as

    relrl_rule_error(Goal, Where, Error)

where Where is File:Line of the first clause of Goal's predicate (or `unknown`), so that a
time limit, a stack overflow or a call to an undefined predicate reaches the robot's loop
and names the rule that caused it. An error already wrapped by an inner goal passes through
unchanged (it names the innermost rule the engine called).
*/

%!  rule_holds(+KB, +Goal) is semidet.
%
%   Goal, a goal of the domain loaded into KB, has a solution.

rule_holds(KB, Goal) :-
    catch(KB:Goal, E, rule_error(KB, Goal, E)),
    !.

%!  rules_mask(+KB, +GoalBits:list, +Mask0, -Mask) is det.
%
%   Mask is Mask0 with the Bit of every Goal-Bit pair of GoalBits whose Goal holds: the
%   state code's facts in one loop. Each Goal runs as under rule_holds/2, with the same
%   errors: one catch/3 guards the loop, which notes (nb_setarg/3 of an integer, a third
%   of the cost of a catch/3 frame) which goal is running, so an exception still names its
%   goal.

rules_mask(KB, GoalBits, Mask0, Mask) :-
    Running = running(0),
    catch(rules_mask_(GoalBits, KB, Running, 1, Mask0, Mask), E,
          rules_error(KB, GoalBits, Running, E)).

rules_mask_([], _, _, _, Mask, Mask).
rules_mask_([Goal-Bit|Gs], KB, Running, I, Mask0, Mask) :-
    nb_setarg(1, Running, I),
    (   KB:Goal
    ->  Mask1 is Mask0 \/ Bit
    ;   Mask1 = Mask0
    ),
    I1 is I + 1,
    rules_mask_(Gs, KB, Running, I1, Mask1, Mask).

rules_error(KB, GoalBits, running(I), E) :-
    (   I > 0
    ->  nth1(I, GoalBits, Goal-_),
        rule_error(KB, Goal, E)
    ;   throw(E)
    ).

%!  rule_solution(+KB, +Goal) is nondet.
%
%   Enumerate the solutions of Goal in KB.

rule_solution(KB, Goal) :-
    catch(KB:Goal, E, rule_error(KB, Goal, E)).

rule_error(_, _, E) :-
    (   E = relrl_rule_error(_, _, _)
    ;   E == '$aborted'
    ),
    !,
    throw(E).
rule_error(KB, Goal, E) :-
    rule_where(KB, Goal, Where),
    throw(relrl_rule_error(Goal, Where, E)).

%!  rule_where(+KB, +Goal, -Where) is det.
%
%   Where is File:Line of the first clause of Goal's predicate in KB, or `unknown`.

rule_where(KB, Goal, Where) :-
    (   callable(Goal),
        \+ predicate_property(KB:Goal, imported_from(_)),
        predicate_property(KB:Goal, file(File)),
        predicate_property(KB:Goal, line_count(Line))
    ->  Where = File:Line
    ;   Where = unknown
    ).
