:- module(relrl_senses,
          [ perceived/3,          % +KB, +Sense, ?What
            sensed/3,             % +Sense, +KB, ?What
            perceived_at/3,       % +KB, ?Stimulus, ?Place
            stimulus_present/2,   % +KB, ?Stimulus
            stimulus_perceived/2, % +KB, +Stimulus
            sense/1               % ?Sense
          ]).
:- use_module(library(error)).
:- use_module(memory).
:- use_module(declarations).

/** <module> Perception predicates over working memory

The perception predicates of section 3.1, see/1, hear/1, at/1 and smell/1 (and the positional
at/2), answer from the current working memory of a knowledge base. Percepts are stored as
memory elements of the same shape: see(face), hear(attention), at(object, left_down).

A perception predicate takes either a stimulus or a fact applied to a stimulus:
`see(face)` holds when see(face) is in memory; `see(frontal(face))` holds when see(face) is
in memory and the domain's fact frontal(face) holds (for example because pose(face, frontal)
is in memory). This is how the paper's necessity inputs such as see(frontal(face)) read.
*/

%!  sense(?Sense) is nondet.
%
%   The senses of the architecture.

sense(see).
sense(hear).
sense(smell).
sense(at).

%!  perceived(+KB, +Sense, ?What) is nondet.
%
%   What is perceived through Sense in KB's working memory. What is a stimulus, or a fact
%   F(S) about a stimulus S that is perceived through Sense.
%
%   @error domain_error(sense, Sense) if Sense is not see, hear, smell or at.

perceived(KB, Sense, What) :-
    must_be(atom, Sense),
    (   sense(Sense)
    ->  true
    ;   domain_error(sense, Sense)
    ),
    sensed(Sense, KB, What).

%!  sensed(+Sense, +KB, ?What) is nondet.
%
%   perceived/3 for a Sense known to be one (no checks): what the perception predicates
%   of relrl.pl call, many times in every control step.

sensed(Sense, KB, What) :-
    (   var(What)
    ->  Percept =.. [Sense, What],
        wm_has(KB, Percept)
    ;   atomic(What)
    ->  compound_name_arguments(Percept, Sense, [What]),
        wm_has_chk(KB, Percept)
    ;   What =.. [_, Stimulus],
        atomic(Stimulus)
    ->  Percept =.. [Sense, Stimulus],
        wm_has_chk(KB, Percept),
        once(KB:What)
    ;   Percept =.. [Sense, What],
        wm_has_chk(KB, Percept)
    ).

%!  perceived_at(+KB, ?Stimulus, ?Place) is nondet.
%
%   Stimulus is perceived at Place (the at/2 percept).

perceived_at(KB, Stimulus, Place) :-
    wm_has(KB, at(Stimulus, Place)).

%!  stimulus_present(+KB, ?Stimulus) is nondet.
%
%   The declared Stimulus is perceived now through some sense (or located with at/2).

stimulus_present(KB, Stimulus) :-
    kb_stimulus(KB, Stimulus),
    stimulus_perceived(KB, Stimulus).

%!  stimulus_perceived(+KB, +Stimulus) is semidet.
%
%   Stimulus is perceived now through some sense (or located with at/2); no check that it
%   is declared.

stimulus_perceived(KB, Stimulus) :-
    wm_has_stimulus(KB, Stimulus).
