:- module(relrl_motivation,
          [ motivation_reset/1,     % +KB
            motivation_step/3,      % +KB, -Outputs, -Active
            motivation_units/2,     % +KB, -Units
            motivation_step/4,      % +KB, +Units, -Outputs, -Active
            motivation_peek/4,      % +KB, +Units, -Outputs, -Active
            motivation_values/6,    % +KB, +Record, +Units, -Outputs, -Ys, -Active
            motivation_compiled/3,  % +KB, +Units0, -Units
            motivation_outputs/2,   % +KB, -Outputs
            motivation_set_outputs/2, % +KB, +Outputs
            unit_activation/5,      % +Inputs, +Wr, +Ir, +Bias, -U
            unit_output/3           % +U, +Delta, -Y
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(declarations).
:- use_module(rules).
:- use_module(kbstate).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

/** <module> Consequence control: necessity units and the mediator

Section 3.2 of da Silva & Romero (2012). Each necessity unit is a perceptron with a
recurrent connection:

    u = sum_j w_j * i_j + w_r * i_r + b          (Eq. 1)
    y = 1 / (1 + exp(-(u + delta)))               (Eq. 2)

i_j is 1 when the j-th input goal holds in working memory and 0 otherwise; i_r is the unit's
own output at the previous step. The mediator picks the unit with the largest output and
makes it the active necessity when its output exceeds the unit's threshold; otherwise the
active necessity is `none`.

Sign convention. The paper gives the inputs of `socialize` positive weights, but if every
input adds to u the unit can never fall below its threshold once contact is made. In a domain
file, unit_input(N, Goal, W) adds W to u when Goal holds, and satisfier(N, Goal, W) subtracts
W: a satisfying stimulus (the caregiver's attention, a frontal face) lowers the need. The
paper's weights are declared as satisfiers with their printed magnitudes.
*/

%   The units' outputs of KB are the `units` part of its record (kbstate.pl), a list of
%   Necessity-Y pairs in declaration order (no assert/retract in the robot's control step).
%   The predicates below that are not given the record find it with kb_record/2.

%!  unit_output(+U, +Delta, -Y) is det.
%
%   Eq. 2.

unit_output(U, Delta, Y) :-
    Y is 1 / (1 + exp(-(U + Delta))).

%!  unit_activation(+Inputs, +Wr, +Ir, +Bias, -U) is det.
%
%   Eq. 1 for Inputs, a list of Weight-Input pairs with Input 0 or 1.

unit_activation(Inputs, Wr, Ir, Bias, U) :-
    foldl(weighted, Inputs, 0, Sum),
    U is Sum + Wr*Ir + Bias.

weighted(W-I, S0, S) :-
    S is S0 + W*I.

%!  motivation_reset(+KB) is det.
%
%   Set every unit's output to its `initial` parameter (default 0).

motivation_reset(KB) :-
    must_be(atom, KB),
    findall(N-Y0, ( kb_necessity(KB, N),
                    unit_parameters(KB, N, Params),
                    memberchk(initial=Y0, Params) ), Outputs),
    kb_set(KB, units, Outputs).

%!  motivation_outputs(+KB, -Outputs:list) is det.
%
%   Outputs is the list of Necessity-Y pairs of the last step.

motivation_outputs(KB, Outputs) :-
    kb_get(KB, units, Outputs).

%!  motivation_set_outputs(+KB, +Outputs:list) is det.
%
%   Put back the unit outputs saved with motivation_outputs/2.

motivation_set_outputs(KB, Outputs) :-
    must_be(list, Outputs),
    kb_set(KB, units, Outputs).

%!  motivation_step(+KB, -Outputs:list, -Active) is det.
%
%   Compute every unit's output from working memory (Eq. 1, 2), remember it for the
%   recurrent connection, and let the mediator choose Active, a necessity or `none`.

motivation_step(KB, Outputs, Active) :-
    motivation_units(KB, Units),
    motivation_step(KB, Units, Outputs, Active).

%!  motivation_units(+KB, -Units:list) is det.
%
%   Units describes every necessity unit of KB as
%   unit(N, Bias, Wr, Delta, Threshold, Initial, Inputs), Inputs = inputs(Goals, Weights)
%   for the unit's inputs (necessity_inputs/3) in order: Goals = goals(GoalBits), Goal-Bit
%   pairs (bit j for the j-th input goal, as relrl_rules:rules_mask/4 takes them), and the
%   weights. The engine computes it once per run (and compiles it, motivation_compiled/3)
%   and passes it to motivation_step/4.

motivation_units(KB, Units) :-
    findall(unit(N, B, Wr, Delta, T, Y0, inputs(goals(GoalBits), Weights)),
            ( kb_necessity(KB, N),
              unit_parameters(KB, N, Params),
              memberchk(bias=B, Params),
              memberchk(recurrent_weight=Wr, Params),
              memberchk(delta=Delta, Params),
              memberchk(threshold=T, Params),
              memberchk(initial=Y0, Params),
              necessity_inputs(KB, N, Inputs),
              input_bits(Inputs, 1, GoalBits, Weights) ),
            Units).

%!  motivation_compiled(+KB, +Units0, -Units) is det.
%
%   Units0 (from motivation_units/2) with each unit's input goals compiled
%   (relrl_rules:rules_program/3): the same outputs, for less work a step.

motivation_compiled(KB, Units0, Units) :-
    maplist(unit_compiled(KB), Units0, Units).

unit_compiled(KB, unit(N, B, Wr, Delta, T, Y0, inputs(goals(GoalBits), Weights)),
              unit(N, B, Wr, Delta, T, Y0, inputs(Program, Weights))) :-
    rules_program(KB, GoalBits, Program).

input_bits([], _, [], []).
input_bits([Goal-W|Is], Bit, [Goal-Bit|Gs], [W|Ws]) :-
    Bit1 is Bit << 1,
    input_bits(Is, Bit1, Gs, Ws).

%!  motivation_step(+KB, +Units, -Outputs:list, -Active) is det.
%
%   As motivation_step/3 with the units from motivation_units/2.

motivation_step(KB, Units, Outputs, Active) :-
    kb_record(KB, Record),
    motivation_values(KB, Record, Units, Outputs, _, Active).

%!  motivation_values(+KB, +Record, +Units, -Outputs:list, -Ys:list, -Active) is det.
%
%   motivation_step/4 that also gives the outputs alone, Ys (in declaration order): the
%   control step's one pass over the units. Record is KB's record (kb_record/2).

motivation_values(KB, Record, Units, Outputs, Ys, Active) :-
    record_get(Record, units, Previous),
    unit_values(Units, KB, Previous, Outputs, Ys),
    record_set(Record, units, Outputs),
    mediate(Units, Outputs, Active).

%!  motivation_peek(+KB, +Units, -Outputs, -Active) is det.
%
%   What motivation_step/4 would give now, without moving the units' state.

motivation_peek(KB, Units, Outputs, Active) :-
    kb_get(KB, units, Previous),
    unit_values(Units, KB, Previous, Outputs, _),
    mediate(Units, Outputs, Active).

%   Eq. 1 and 2 for every unit; Ir, the recurrent input, is the unit's previous output.
unit_values([], _, _, [], []).
unit_values([unit(N, B, Wr, Delta, _, Y0, inputs(Goals, Weights))|Us], KB, Previous,
            [N-Y|Os], [Y|Ys]) :-
    (   memberchk(N-Ir, Previous)
    ->  true
    ;   Ir = Y0
    ),
    inputs_holding(Goals, KB, Holds),
    inputs_sum(Weights, Holds, 1, 0, Sum),
    U is Sum + Wr*Ir + B,
    Y is 1 / (1 + exp(-(U + Delta))),
    unit_values(Us, KB, Previous, Os, Ys).

inputs_holding(goals(GoalBits), KB, Holds) :-
    rules_mask(KB, GoalBits, 0, Holds).
inputs_holding(program(Id, KB, GoalBits), _, Holds) :-
    program_mask(program(Id, KB, GoalBits), 0, Holds).

%   sum_j w_j * i_j, i_j 1 when the j-th input goal holds (bit j of Holds):
%   unit_activation/5's sum, term by term (the same floating-point operations in the same
%   order).
inputs_sum([], _, _, Sum, Sum).
inputs_sum([W|Ws], Holds, Bit, Sum0, Sum) :-
    (   Holds /\ Bit =\= 0
    ->  I = 1
    ;   I = 0
    ),
    Sum1 is Sum0 + W*I,
    Bit1 is Bit << 1,
    inputs_sum(Ws, Holds, Bit1, Sum1, Sum).

mediate(_, [], none) :- !.
mediate(Units, Outputs, Active) :-
    strongest(Outputs, none, -1.0, Best, Y),
    memberchk(unit(Best, _, _, _, T, _, _), Units),
    (   Y > T
    ->  Active = Best
    ;   Active = none
    ).

%   The first unit with the largest output.
strongest([], Best, Y, Best, Y).
strongest([N-Y|Os], Best0, Y0, Best, YBest) :-
    (   Y > Y0
    ->  strongest(Os, N, Y, Best, YBest)
    ;   strongest(Os, Best0, Y0, Best, YBest)
    ).
