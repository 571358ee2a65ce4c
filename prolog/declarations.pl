:- module(relrl_declarations,
          [ declared/2,             % +KB, ?Declaration
            kb_stimulus/2,          % +KB, ?Stimulus
            kb_fact/2,              % +KB, ?Fact
            kb_response/2,          % +KB, ?Response
            kb_necessity/2,         % +KB, ?Necessity
            kb_reinforcer/2,        % +KB, ?Stimulus
            unit_parameter/4,       % +KB, ?Necessity, ?Param, ?Value
            unit_parameters/3,      % +KB, +Necessity, -Params:dict-like list
            necessity_inputs/3,     % +KB, +Necessity, -Inputs
            unit_parameter_name/1,  % ?Param
            behaviour_rule/5,       % +KB, ?Antecedent, ?Response, ?Necessity, ?Fitness
            declaration_predicate/1 % ?PredicateIndicator
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).

/** <module> Domain declarations

A domain file declares, as plain Prolog clauses:

  | stimulus(Name)                   | a stimulus the robot can perceive                 |
  | stimulus_property(Name, Prop)    | a property of a stimulus, e.g. `reinforcer`       |
  | fact(Term)                       | a named fact; Term is also the goal defining it   |
  | response(Term)                   | a response the robot can emit                     |
  | necessity(Name)                  | a necessity unit of the motivational system       |
  | unit(Name, Param, Value)         | bias, recurrent_weight, delta, threshold, initial |
  | unit_input(Name, Goal, W)        | an input of Eq. 1 that raises the need (+W)       |
  | satisfier(Name, Goal, W)         | an input that satisfies the need: enters Eq. 1 as -W |
  | behaviour(Antecedent, Response, Necessity, Fitness) | a behaviour rule (three-term contingency) |
  | forbidden(Response) :- Body      | a constraint rule: Response is not allowed when Body holds |
  | memory_span(N)                   | optional: how many steps percepts stay in memory |
  | etg_test(Goal)                   | optional: extra first-order tests for the ETG tree |

This module enumerates those declarations for a knowledge base KB (the module the domain
was loaded into; `user` when it was consulted at the swipl prompt). A declaration the domain
does not define at all is simply absent (no existence errors).

Declarations and definitions may interleave, and a domain may be spread over several files:
before a file is loaded into a knowledge base, relrl declares the declaration predicates
(declaration_predicate/1) discontiguous and multifile in it, so `fact(frontal(face)).` may
sit right above `frontal(face) :- ...` and a `response/1` may come at the end of the file.
*/

%!  declared(+KB, ?Declaration) is nondet.
%
%   Declaration is a clause head the domain of KB defines, e.g. stimulus(face). Succeeds
%   without error (and without solutions) when the domain does not define the predicate.

declared(KB, Declaration) :-
    must_be(atom, KB),
    callable(Declaration),
    functor(Declaration, Name, Arity),
    (   current_predicate(KB:Name/Arity),
        \+ predicate_property(KB:Declaration, imported_from(_))
    ->  KB:Declaration
    ;   fail
    ).

%!  kb_stimulus(+KB, ?Stimulus) is nondet.
%!  kb_fact(+KB, ?Fact) is nondet.
%!  kb_response(+KB, ?Response) is nondet.
%!  kb_necessity(+KB, ?Necessity) is nondet.
%
%   Enumerate the declarations of KB in declaration order.

kb_stimulus(KB, S)  :- declared(KB, stimulus(S)).
kb_fact(KB, F)      :- declared(KB, fact(F)).
kb_response(KB, R)  :- declared(KB, response(R)).
kb_necessity(KB, N) :- declared(KB, necessity(N)).

%!  kb_reinforcer(+KB, ?Stimulus) is nondet.
%
%   Stimulus is declared a reinforcer: perceiving it is a positive consequence.

kb_reinforcer(KB, S) :-
    declared(KB, stimulus_property(S, reinforcer)).

%!  unit_parameter_name(?Param) is nondet.
%
%   The parameters a necessity unit takes. `initial` (the output before the first step) is
%   optional and defaults to 0; the others are required.

unit_parameter_name(bias).
unit_parameter_name(recurrent_weight).
unit_parameter_name(delta).
unit_parameter_name(threshold).
unit_parameter_name(initial).

%!  unit_parameter(+KB, ?Necessity, ?Param, ?Value) is nondet.
%
%   A declared parameter of a necessity unit (unit/3 in the domain).

unit_parameter(KB, N, Param, Value) :-
    declared(KB, unit(N, Param, Value)).

%!  unit_parameters(+KB, +Necessity, -Params:list) is det.
%
%   Params is [bias=B, recurrent_weight=Wr, delta=D, threshold=T, initial=Y0] for the unit.
%
%   @error existence_error(unit_parameter, N-Param) if a required parameter is missing.
%   @error type_error(number, Value) if a parameter is not a number.

unit_parameters(KB, N, Params) :-
    must_be(atom, KB),
    must_be(atom, N),
    findall(P=V, ( unit_parameter_name(P), unit_value(KB, N, P, V) ), Params).

unit_value(KB, N, P, V) :-
    (   unit_parameter(KB, N, P, V0)
    ->  must_be(number, V0),
        V = V0
    ;   P == initial
    ->  V = 0
    ;   existence_error(unit_parameter, N-P)
    ).

%!  necessity_inputs(+KB, +Necessity, -Inputs:list) is det.
%
%   Inputs is a list of Goal-Weight pairs, the inputs of Eq. 1 for the unit, in declaration
%   order. Satisfiers (satisfier/3) appear with their weight negated: satisfying stimuli
%   lower the need.

necessity_inputs(KB, N, Inputs) :-
    findall(Goal-W,
            (   declared(KB, unit_input(N, Goal, W))
            ;   declared(KB, satisfier(N, Goal, W0)), W is -W0
            ),
            Inputs).

%!  behaviour_rule(+KB, ?Antecedent, ?Response, ?Necessity, ?Fitness) is nondet.
%
%   An authored behaviour rule of the domain (behaviour/4).

behaviour_rule(KB, A, R, N, F) :-
    declared(KB, behaviour(A, R, N, F)).

%!  declaration_predicate(?PI) is nondet.
%
%   PI (Name/Arity) is a predicate a domain declares with: its clauses may be spread over
%   the file and over several files of one knowledge base.

declaration_predicate(stimulus/1).
declaration_predicate(stimulus_property/2).
declaration_predicate(fact/1).
declaration_predicate(response/1).
declaration_predicate(necessity/1).
declaration_predicate(unit/3).
declaration_predicate(unit_input/3).
declaration_predicate(satisfier/3).
declaration_predicate(behaviour/4).
declaration_predicate(forbidden/1).
declaration_predicate(memory_span/1).
declaration_predicate(etg_test/1).
declaration_predicate(relation/1).
declaration_predicate(rmode/1).
declaration_predicate(rconst/2).

%   A domain file loaded into a knowledge base (a module that imports relrl, see
%   relrl_gateway:gw_new_kb/1) starts with the declarations relrl needs. Module files (a
%   library autoloaded while a query runs in a knowledge base) are left alone.

:- multifile user:term_expansion/2.
:- dynamic user:term_expansion/2.

user:term_expansion(begin_of_file, [begin_of_file|Directives]) :-
    prolog_load_context(module, Module),
    Module \== relrl,
    import_module(Module, relrl),
    prolog_load_context(file, File),
    \+ module_file(File),
    findall((:- Declaration),
            (   declaration_predicate(PI),
                member(Declaration, [discontiguous(Module:PI), multifile(Module:PI)])
            ),
            Directives).

module_file(File) :-
    access_file(File, read),
    exists_file(File),
    setup_call_cleanup(
        open(File, read, Stream),
        read_term(Stream, First, [syntax_errors(quiet)]),
        close(Stream)),
    First = (:- module(_, _)).
