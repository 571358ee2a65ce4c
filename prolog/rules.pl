:- module(relrl_rules,
          [ rule_holds/2,         % +KB, +Goal
            rules_mask/4,         % +KB, +GoalBits, +Mask0, -Mask
            rules_program/3,      % +KB, +GoalBits, -Program
            program_mask/3,       % +Program, +Mask0, -Mask
            rules_mark/1,         % -Mark
            rules_forget/1,       % +KB
            rules_forget/2,       % +KB, +Mark
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

%!  rules_program(+KB, +GoalBits:list, -Program) is det.
%!  program_mask(+Program, +Mask0, -Mask) is det.
%
%   rules_mask/4 for a list of goals run many times (the state code's facts, a necessity
%   unit's inputs): rules_program/3 compiles one clause that calls each goal of GoalBits
%   directly (no call/1 of a goal term at run time, a fifth less time); program_mask/3 runs
%   it, with rules_mask/4's results and errors. A program lasts until rules_forget/1 (the
%   engine forgets a KB's programs when it is configured again and when it is dropped).
%
%   The clause is KB's own, '$relrl_program'(Id, Running, Mask0, Mask): its goals are
%   KB's, and it goes with KB's module when the knowledge base is dropped (a clause of
%   another module may not name a knowledge base's module, which is destroyed then).

rules_program(KB, GoalBits, program(Id, KB, GoalBits)) :-
    must_be(atom, KB),
    must_be(list, GoalBits),
    flag(relrl_rules_program, Id, Id + 1),
    program_body(GoalBits, Running, 1, Mask0, Mask, Body),
    assertz(KB:('$relrl_program'(Id, Running, Mask0, Mask) :- Body)).

program_body([], _, _, Mask0, Mask, Mask = Mask0).
program_body([Goal-Bit|Gs], Running, I, Mask0, Mask,
             ( nb_setarg(1, Running, I),
               (   Goal
               ->  Mask1 is Mask0 \/ Bit
               ;   Mask1 = Mask0
               ),
               Rest )) :-
    must_be(callable, Goal),
    must_be(integer, Bit),
    I1 is I + 1,
    program_body(Gs, Running, I1, Mask1, Mask, Rest).

program_mask(program(Id, KB, GoalBits), Mask0, Mask) :-
    Running = running(0),
    catch(KB:'$relrl_program'(Id, Running, Mask0, Mask), E,
          rules_error(KB, GoalBits, Running, E)).

%!  rules_mark(-Mark) is det.
%!  rules_forget(+KB) is det.
%!  rules_forget(+KB, +Mark) is det.
%
%   Forget KB's programs: all of them, or those made before rules_mark/1 gave Mark (the
%   engine drops a run's programs once the next run is in place).

rules_mark(Mark) :-
    flag(relrl_rules_program, Mark, Mark).

rules_forget(KB) :-
    rules_forget(KB, inf).

rules_forget(KB, Mark) :-
    (   current_predicate(KB:'$relrl_program'/4)
    ->  forall(( clause(KB:'$relrl_program'(Id, _, _, _), _, Ref), Id < Mark ),
               erase(Ref))
    ;   true
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
