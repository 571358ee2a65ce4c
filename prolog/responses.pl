:- module(relrl_responses,
          [ allowed_response/2,   % +KB, ?Response
            allowed_responses/2,  % +KB, -Responses
            forbidden_response/2  % +KB, ?Response
          ]).
:- use_module(declarations).

/** <module> Responses allowed under the constraint rules

A constraint rule of a domain says when a response is not allowed:

    forbidden(look(left)) :- at(left).      % already looking left

A response is allowed in the current state when it is declared and no constraint rule
forbids it. Learners only ever choose among the allowed responses.
*/

%!  forbidden_response(+KB, ?Response) is nondet.
%
%   A constraint rule of KB forbids Response now.

forbidden_response(KB, Response) :-
    kb_response(KB, Response),
    once(declared(KB, forbidden(Response))).

%!  allowed_response(+KB, ?Response) is nondet.
%
%   Response is declared and no constraint rule forbids it now.

allowed_response(KB, Response) :-
    kb_response(KB, Response),
    \+ declared(KB, forbidden(Response)).

%!  allowed_responses(+KB, -Responses:list) is det.
%
%   Responses are the allowed responses in declaration order.

allowed_responses(KB, Responses) :-
    findall(R, allowed_response(KB, R), Responses).
