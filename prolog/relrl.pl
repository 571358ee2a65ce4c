:- module(relrl,
          [ see/1,                % ?What
            hear/1,               % ?What
            smell/1,              % ?What
            at/1,                 % ?What
            at/2,                 % ?Stimulus, ?Place
            percept/1,            % ?Element
            memory/2,             % ?Element, ?Age
            remember/1,           % +Elements
            forget_all/0,
            list_memory/0,
            state/1,              % -Code
            state_terms/1,        % -Terms
            decode_state/2,       % +Code, -Terms
            encode_state/2,       % +Terms, -Code
            feature_code/2,       % ?Term, ?X
            list_state_codes/0,
            allowed/1,            % ?Response
            allowed_responses/1,  % -Responses
            op(200, fy, #)        % #Type: a constant of Type in a language bias (rmode/1)
          ]).
:- use_module(library(arithmetic)).   % the same arithmetic checks for every load
:- use_module(memory).
:- use_module(declarations).
:- use_module(senses).
:- use_module(state).
:- use_module(responses).
:- use_module(check).
:- use_module(percept_check).
:- use_module(engine).
:- use_module(learners).
:- use_module(policy).
:- use_module(world).
:- use_module(world_check).
:- use_module(world_states).

/** <module> relrl: the knowledge layer

Consult this file, then a domain file, and query the knowledge base at the swipl prompt:

    $ swipl prolog/relrl.pl examples/domains/fruits.pl
    ?- stimulus(S).
    ?- remember([see(face), pose(face, frontal), hear(attention)]).
    ?- see(frontal(face)).
    ?- state(Code), decode_state(Code, Terms).
    ?- allowed(R).

The predicates here work on the knowledge base of the module they are called from (the
*context module*): `user` at the prompt, or the module relrl's Python gateway loaded the
domain into. Each has an explicit-knowledge-base twin in the module named in its
documentation, which is what programs should call.
*/

:- module_transparent
    see/1, hear/1, smell/1, at/1, at/2, percept/1, memory/2, remember/1, forget_all/0,
    list_memory/0, state/1, state_terms/1, decode_state/2, encode_state/2, feature_code/2,
    list_state_codes/0, allowed/1, allowed_responses/1, kb/1.

kb(KB) :-
    context_module(KB).

%   relrl_domains(Name) is the folder of the shipped domains, examples/domains beside this
%   file's folder in a checkout and in an installed package alike. A domain takes their
%   shared parts from it wherever the domain file lies: :- include(relrl_domains(socialize)).

:- multifile user:file_search_path/2.
:- dynamic user:file_search_path/2.

user:file_search_path(relrl_domains, Dir) :-
    module_property(relrl, file(File)),
    file_directory_name(File, PrologDir),
    directory_file_path(PrologDir, '../examples/domains', Dir).

%!  see(?What) is nondet.
%!  hear(?What) is nondet.
%!  smell(?What) is nondet.
%!  at(?What) is nondet.
%
%   Perception predicates over working memory; see relrl_senses:perceived/3.

see(What)   :- context_module(KB), sensed(see, KB, What).
hear(What)  :- context_module(KB), sensed(hear, KB, What).
smell(What) :- context_module(KB), sensed(smell, KB, What).
at(What)    :- context_module(KB), sensed(at, KB, What).

%!  at(?Stimulus, ?Place) is nondet.
%
%   Stimulus is perceived at Place.

at(Stimulus, Place) :- context_module(KB), wm_has(KB, at(Stimulus, Place)).

%!  percept(?Element) is nondet.
%
%   Element is in working memory (any age). Use it for stimulus properties:
%   `frontal(face) :- percept(pose(face, frontal)).`

percept(Element) :- context_module(KB), wm_has(KB, Element).

%!  memory(?Element, ?Age) is nondet.
%
%   Element is in working memory with age Age.

memory(Element, Age) :-
    context_module(KB),
    (   Age == 0
    ->  wm_now(KB, Element)
    ;   wm_element(KB, Element, Age)
    ).

%!  remember(+Elements:list) is det.
%
%   One insertion into working memory (see relrl_memory:wm_insert/2).

remember(Elements) :- kb(KB), wm_insert(KB, Elements).

%!  forget_all is det.
%
%   Empty working memory.

forget_all :- kb(KB), wm_clear(KB).

%!  list_memory is det.
%
%   Print working memory, one element a line with its age.

list_memory :-
    kb(KB),
    wm_elements(KB, Pairs),
    forall(member(Age-E, Pairs), format("~t~d~6|  ~q~n", [Age, E])).

%!  state(-Code:integer) is det.
%
%   Code is the current state code (relrl_state:state_code/2).

state(Code) :- kb(KB), state_code(KB, Code).

%!  state_terms(-Terms:list) is det.
%
%   The stimuli and facts that hold now, in code order.

state_terms(Terms) :- kb(KB), relrl_state:state_terms(KB, Terms).

%!  decode_state(+Code, -Terms:list) is det.
%!  encode_state(+Terms:list, -Code) is det.
%
%   Convert between a state code and its features.

decode_state(Code, Terms) :- kb(KB), state_decode(KB, Code, Terms).
encode_state(Terms, Code) :- kb(KB), state_encode(KB, Terms, Code).

%!  feature_code(?Term, ?X) is nondet.
%
%   The stimulus(S) or fact(F) Term has index X; its code is 2^X.

feature_code(Term, X) :- kb(KB), relrl_state:feature_code(KB, Term, X).

%!  list_state_codes is det.
%
%   Print every stimulus and fact with x and 2^x.

list_state_codes :-
    kb(KB),
    forall(relrl_state:feature_code(KB, T, X),
           ( Code is 1 << X,
             format("~t~d~4|  ~t~d~16|  ~q~n", [X, Code, T]) )).

%!  allowed(?Response) is nondet.
%
%   Response is allowed now under the constraint rules.

allowed(Response) :- kb(KB), allowed_response(KB, Response).

%!  allowed_responses(-Responses:list) is det.
%
%   The allowed responses, in declaration order.

allowed_responses(Responses) :- kb(KB), relrl_responses:allowed_responses(KB, Responses).
