; A lifted domain distilled from the transition model ef601c919d80ef7a by symlearn.
; Blocks stand at locations l0-l5 (far row l0-l2, near row l3-l5) on a support, at a level (5 cm layers).
(define (domain symlearn-ef601c919d80ef7a)
  (:requirements :strips :typing)
  (:types
    block location layer position - object
    cube stick - block)
  (:constants l0 l1 l2 l3 l4 l5 - location on-spot minus-y-near minus-y-mid minus-y-far plus-y-near plus-y-mid plus-y-far off-x - position
    h0 h1 h2 h3 h4 h5 h6 h7 h1-end h2-end h3-end h4-end h5-end h6-end h7-end - layer)
  (:predicates (at ?b - block ?l - location) (level ?b - block ?h - layer)
               (stands ?b - block ?l - location ?h - layer) (vacant ?l - location ?h - layer)
               (rests ?b - block ?t - layer) (height ?l - location ?t - layer) (same-level ?t - layer ?h - layer)
               (beneath ?l - location ?h - layer) (place ?b - block ?p - position)
               (near ?l - location) (differ ?a - location ?b - location) (is ?a - location ?b - location)
               (hand-empty) (holding ?b - block) (liftable ?h - layer ?t - layer)
               (bit-0 ?b - block) (bit-5 ?b - block)
               (pair-move-0 ?from - location ?to - location ?n1 - location) (pair-move-1 ?from - location ?to - location ?n1 - location) (pair-move-2 ?from - location ?to - location ?n1 - location) (pair-move-3 ?from - location ?to - location ?n1 - location) (pair-move-4 ?from - location ?to - location ?n1 - location ?n2 - location) (pair-move-5 ?from - location ?to - location ?n1 - location ?n2 - location) (pair-move-6 ?from - location ?to - location ?n1 - location) (pair-move-7 ?from - location ?to - location) (pair-move-8 ?from - location ?to - location ?n1 - location) (pair-move-9 ?from - location ?to - location ?n1 - location) (pair-move-10 ?from - location ?to - location ?n1 - location) (pair-move-11 ?from - location ?to - location ?n1 - location) (pair-move-12 ?from - location ?to - location ?n1 - location) (pair-move-13 ?from - location ?to - location ?n1 - location ?n2 - location) (pair-move-14 ?from - location ?to - location ?n1 - location ?n2 - location) (pair-move-15 ?from - location ?to - location ?n1 - location ?n2 - location) (pair-move-16 ?from - location ?to - location ?n1 - location ?n2 - location) (pair-move-17 ?from - location ?to - location ?n1 - location ?n2 - location) (pair-move-18 ?from - location ?to - location ?n1 - location ?n2 - location) (pair-move-19 ?from - location ?to - location ?n1 - location))
  ; a cube is lifted off the top of its location, which drops to what it rested on; its level and what
  ; it rested on stay with it until a release-cube action puts it down (liftable: the pairs some does)
  (:action pick-cube
    :parameters (?o - cube ?from - location ?h - layer ?t - layer)
    :precondition (and (hand-empty) (liftable ?h ?t) (stands ?o ?from ?h) (rests ?o ?t) (height ?from ?h))
    :effect (and (not (hand-empty)) (holding ?o) (not (at ?o ?from)) (not (stands ?o ?from ?h))
      (not (height ?from ?h)) (height ?from ?t) (vacant ?from ?h)))
  ; 3219 moves: a cube lands on its release location at level 2
  (:action release-cube-0
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (differ ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (bit-0 ?o) (not (bit-5 ?o))
      (not (height ?to h0)) (height ?to h2) (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 895 moves: a cube lands on its release location at level 2
  (:action release-cube-to-l2-1
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (is ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (bit-0 ?o) (bit-5 ?o)
      (not (height ?to h0)) (height ?to h2) (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 135 moves: a cube lands on its release location at level 3
  (:action release-cube-2
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (height ?to h1-end)
      (vacant ?to h3))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h1-end)
      (not (level ?o h2)) (level ?o h3) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h1-end)) (height ?to h3)
      (stands ?o ?to h3) (not (vacant ?to h3))))
  ; 640 moves: a cube lands on its release location at level 3
  (:action release-cube-3
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (differ ?to l4)
      (height ?to h1) (vacant ?to h3))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h1)
      (not (level ?o h2)) (level ?o h3) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h1)) (height ?to h3)
      (stands ?o ?to h3) (not (vacant ?to h3))))
  ; 170 moves: a cube lands on its release location at level 3
  (:action release-cube-to-l4-4
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (is ?to l4)
      (height ?to h1) (vacant ?to h3))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h1)
      (not (level ?o h2)) (level ?o h3) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h1))
      (height ?to h3) (stands ?o ?to h3) (not (vacant ?to h3))))
  ; 635 moves: a cube lands on its release location at level 4
  (:action release-cube-5
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (differ ?to l3)
      (height ?to h2) (vacant ?to h4))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h2)
      (not (level ?o h2)) (level ?o h4) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h2))
      (height ?to h4) (stands ?o ?to h4) (not (vacant ?to h4))))
  ; 196 moves: a cube lands on its release location at level 4
  (:action release-cube-to-l3-6
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (is ?to l3)
      (height ?to h2) (vacant ?to h4))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h2)
      (not (level ?o h2)) (level ?o h4) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h2)) (height ?to h4)
      (stands ?o ?to h4) (not (vacant ?to h4))))
  ; 51 moves: a cube ends off its release location at level 1
  (:action release-cube-7
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (height ?to h3-end)
      (vacant ?to h1))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h3-end)
      (not (place ?o on-spot)) (place ?o plus-y-near) (not (level ?o h2)) (level ?o h1) (bit-0 ?o) (bit-5 ?o)
      (not (height ?to h3-end)) (height ?to h1) (stands ?o ?to h1) (not (vacant ?to h1))))
  ; 333 moves: a cube lands on its release location at level 5
  (:action release-cube-8
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (height ?to h3)
      (vacant ?to h5))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h3)
      (not (level ?o h2)) (level ?o h5) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h3))
      (height ?to h5) (stands ?o ?to h5) (not (vacant ?to h5))))
  ; 103 moves: a cube lands on its release location at level 6
  (:action release-cube-9
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (height ?to h4)
      (vacant ?to h6))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h4)
      (not (level ?o h2)) (level ?o h6) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h4))
      (height ?to h6) (stands ?o ?to h6) (not (vacant ?to h6))))
  ; 46 moves: a cube lands on its release location at level 7
  (:action release-cube-10
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h0) (place ?o on-spot) (height ?to h5)
      (vacant ?to h7))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h0)) (rests ?o h5)
      (not (level ?o h2)) (level ?o h7) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h5))
      (height ?to h7) (stands ?o ?to h7) (not (vacant ?to h7))))
  ; 82 moves: a cube lands on its release location at level 2
  (:action release-cube-11
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h1) (place ?o on-spot) (differ ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h1)) (rests ?o h0)
      (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h0)) (height ?to h2) (stands ?o ?to h2)
      (not (vacant ?to h2))))
  ; 28 moves: a cube lands on its release location at level 2
  (:action release-cube-to-l2-12
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h1) (place ?o on-spot) (is ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h1)) (rests ?o h0)
      (bit-0 ?o) (bit-5 ?o) (not (height ?to h0)) (height ?to h2) (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 53 moves: a cube lands on its release location at level 2
  (:action release-cube-13
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h3) (rests ?o h1-end) (place ?o on-spot) (height ?to h0)
      (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h1-end)) (rests ?o h0)
      (not (level ?o h3)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 396 moves: a cube lands on its release location at level 2
  (:action release-cube-14
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h3) (rests ?o h1) (place ?o on-spot) (differ ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h1)) (rests ?o h0)
      (not (level ?o h3)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 90 moves: a cube lands on its release location at level 2
  (:action release-cube-to-l2-15
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h3) (rests ?o h1) (place ?o on-spot) (is ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h1)) (rests ?o h0)
      (not (level ?o h3)) (level ?o h2) (bit-0 ?o) (bit-5 ?o) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 21 moves: a cube lands on its release location at level 3
  (:action release-cube-16
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h3) (rests ?o h1) (place ?o on-spot) (height ?to h1-end)
      (vacant ?to h3))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h1)) (rests ?o h1-end)
      (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h1-end)) (height ?to h3) (stands ?o ?to h3)
      (not (vacant ?to h3))))
  ; 106 moves: a cube lands on its release location at level 4
  (:action release-cube-17
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h3) (rests ?o h1) (place ?o on-spot) (height ?to h2)
      (vacant ?to h4))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h1)) (rests ?o h2)
      (not (level ?o h3)) (level ?o h4) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h2))
      (height ?to h4) (stands ?o ?to h4) (not (vacant ?to h4))))
  ; 640 moves: a cube lands on its release location at level 2
  (:action release-cube-18
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h4) (rests ?o h2) (place ?o on-spot) (differ ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h2)) (rests ?o h0)
      (not (level ?o h4)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 146 moves: a cube lands on its release location at level 2
  (:action release-cube-to-l2-19
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h4) (rests ?o h2) (place ?o on-spot) (is ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h2)) (rests ?o h0)
      (not (level ?o h4)) (level ?o h2) (bit-0 ?o) (bit-5 ?o) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 31 moves: a cube lands on its release location at level 3
  (:action release-cube-20
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h4) (rests ?o h2) (place ?o on-spot) (height ?to h1-end)
      (vacant ?to h3))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h2)) (rests ?o h1-end)
      (not (level ?o h4)) (level ?o h3) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h1-end)) (height ?to h3)
      (stands ?o ?to h3) (not (vacant ?to h3))))
  ; 113 moves: a cube lands on its release location at level 3
  (:action release-cube-21
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h4) (rests ?o h2) (place ?o on-spot) (differ ?to l4)
      (height ?to h1) (vacant ?to h3))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h2)) (rests ?o h1)
      (not (level ?o h4)) (level ?o h3) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h1)) (height ?to h3)
      (stands ?o ?to h3) (not (vacant ?to h3))))
  ; 31 moves: a cube lands on its release location at level 3
  (:action release-cube-to-l4-22
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h4) (rests ?o h2) (place ?o on-spot) (is ?to l4)
      (height ?to h1) (vacant ?to h3))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h2)) (rests ?o h1)
      (not (level ?o h4)) (level ?o h3) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h1))
      (height ?to h3) (stands ?o ?to h3) (not (vacant ?to h3))))
  ; 74 moves: a cube lands on its release location at level 4
  (:action release-cube-23
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h4) (rests ?o h2) (place ?o on-spot) (differ ?to l3)
      (height ?to h2) (vacant ?to h4))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (bit-0 ?o)) (not (bit-5 ?o))
      (not (height ?to h2)) (height ?to h4) (stands ?o ?to h4) (not (vacant ?to h4))))
  ; 20 moves: a cube lands on its release location at level 4
  (:action release-cube-to-l3-24
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h4) (rests ?o h2) (place ?o on-spot) (is ?to l3)
      (height ?to h2) (vacant ?to h4))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (bit-0 ?o) (not (bit-5 ?o))
      (not (height ?to h2)) (height ?to h4) (stands ?o ?to h4) (not (vacant ?to h4))))
  ; 37 moves: a cube lands on its release location at level 5
  (:action release-cube-25
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h4) (rests ?o h2) (place ?o on-spot) (height ?to h3)
      (vacant ?to h5))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h2)) (rests ?o h3)
      (not (level ?o h4)) (level ?o h5) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h3))
      (height ?to h5) (stands ?o ?to h5) (not (vacant ?to h5))))
  ; 182 moves: a cube lands on its release location at level 2
  (:action release-cube-26
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h5) (rests ?o h3) (place ?o on-spot) (differ ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h3)) (rests ?o h0)
      (not (level ?o h5)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 48 moves: a cube lands on its release location at level 2
  (:action release-cube-to-l2-27
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h5) (rests ?o h3) (place ?o on-spot) (is ?to l2)
      (height ?to h0) (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h3)) (rests ?o h0)
      (not (level ?o h5)) (level ?o h2) (bit-0 ?o) (bit-5 ?o) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 32 moves: a cube lands on its release location at level 4
  (:action release-cube-28
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h5) (rests ?o h3) (place ?o on-spot) (height ?to h2)
      (vacant ?to h4))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h3)) (rests ?o h2)
      (not (level ?o h5)) (level ?o h4) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h2))
      (height ?to h4) (stands ?o ?to h4) (not (vacant ?to h4))))
  ; 89 moves: a cube lands on its release location at level 1
  (:action release-cube-29
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h5) (rests ?o h4) (place ?o on-spot) (height ?to h0)
      (vacant ?to h1))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h4)) (rests ?o h0)
      (not (level ?o h5)) (level ?o h1) (bit-0 ?o) (bit-5 ?o) (not (height ?to h0)) (height ?to h1)
      (stands ?o ?to h1) (not (vacant ?to h1))))
  ; 74 moves: a cube lands on its release location at level 2
  (:action release-cube-30
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h6) (rests ?o h4) (place ?o on-spot) (height ?to h0)
      (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h4)) (rests ?o h0)
      (not (level ?o h6)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 33 moves: a cube lands on its release location at level 2
  (:action release-cube-31
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h7) (rests ?o h5) (place ?o on-spot) (height ?to h0)
      (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h5)) (rests ?o h0)
      (not (level ?o h7)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?to h0)) (height ?to h2)
      (stands ?o ?to h2) (not (vacant ?to h2))))
  ; 21 moves: a cube ends off its release location at level 2
  (:action release-cube-32
    :parameters (?o - cube ?to - location)
    :precondition (and (holding ?o) (level ?o h2) (rests ?o h1) (place ?o minus-y-near) (height ?to h0)
      (vacant ?to h2))
    :effect (and (not (holding ?o)) (hand-empty) (at ?o ?to) (not (rests ?o h1)) (rests ?o h0)
      (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?to h0)) (height ?to h2) (stands ?o ?to h2)
      (not (vacant ?to h2))))
  ; 318 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-33
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h1) (rests ?o h0) (place ?o on-spot)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h1) (height ?to h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h1))
      (height ?from h0) (not (height ?to h0)) (height ?to h1) (not (stands ?o ?from h1)) (stands ?o ?to h1)
      (not (vacant ?to h1)) (vacant ?from h1)))
  ; 251 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-34
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h1) (rests ?o h0) (place ?o on-spot)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h1) (height ?to h2) (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h0)) (rests ?o h2)
      (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?from h1))
      (height ?from h0) (not (height ?to h2)) (height ?to h3) (not (stands ?o ?from h1)) (stands ?o ?to h3)
      (not (vacant ?to h3)) (vacant ?from h1)))
  ; 61 moves: a stick lands on its release location at level 5
  (:action pick-release-stick-35
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h1) (rests ?o h0) (place ?o on-spot)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h1) (height ?to h4) (vacant ?to h5))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h0)) (rests ?o h4)
      (not (level ?o h1)) (level ?o h5) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?from h1))
      (height ?from h0) (not (height ?to h4)) (height ?to h5) (not (stands ?o ?from h1)) (stands ?o ?to h5)
      (not (vacant ?to h5)) (vacant ?from h1)))
  ; 34 moves: a stick lands on its release location at level 2
  (:action pick-release-stick-36
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h3) (rests ?o h1) (place ?o on-spot)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h3) (height ?to h0) (vacant ?to h2))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h1)) (rests ?o h0)
      (not (level ?o h3)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height ?from h3)) (height ?from h1)
      (not (height ?to h0)) (height ?to h2) (not (stands ?o ?from h3)) (stands ?o ?to h2)
      (not (vacant ?to h2)) (vacant ?from h3)))
  ; 117 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-37
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h3) (rests ?o h2) (place ?o on-spot)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h3) (height ?to h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h2)) (rests ?o h0)
      (not (level ?o h3)) (level ?o h1) (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h3)) (height ?from h2)
      (not (height ?to h0)) (height ?to h1) (not (stands ?o ?from h3)) (stands ?o ?to h1)
      (not (vacant ?to h1)) (vacant ?from h3)))
  ; 40 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-38
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h3) (rests ?o h2) (place ?o on-spot)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h3) (height ?to h2) (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (bit-0 ?o)) (not (bit-5 ?o))
      (not (height ?from h3)) (height ?from h2) (not (height ?to h2)) (height ?to h3)
      (not (stands ?o ?from h3)) (stands ?o ?to h3) (not (vacant ?to h3)) (vacant ?from h3)))
  ; 30 moves: a stick ends off its release location at level 1
  (:action pick-release-stick-39
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h1) (rests ?o h0) (place ?o minus-y-mid)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h1) (height ?to h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (place ?o minus-y-mid)) (place ?o minus-y-near)
      (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h1)) (height ?from h0) (not (height ?to h0))
      (height ?to h1) (not (stands ?o ?from h1)) (stands ?o ?to h1) (not (vacant ?to h1)) (vacant ?from h1)))
  ; 37 moves: a stick ends off its release location at level 1
  (:action pick-release-stick-40
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h1) (rests ?o h0) (place ?o plus-y-mid)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h1) (height ?to h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h1))
      (height ?from h0) (not (height ?to h0)) (height ?to h1) (not (stands ?o ?from h1)) (stands ?o ?to h1)
      (not (vacant ?to h1)) (vacant ?from h1)))
  ; 22 moves: a stick ends off its release location at level 1
  (:action pick-release-stick-41
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (stands ?o ?from h3) (rests ?o h2) (place ?o plus-y-mid)
      (differ ?from ?to) (near ?from) (near ?to) (height ?from h3) (height ?to h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h2)) (rests ?o h0)
      (not (place ?o plus-y-mid)) (place ?o plus-y-near) (not (level ?o h3)) (level ?o h1) (not (bit-0 ?o))
      (bit-5 ?o) (not (height ?from h3)) (height ?from h2) (not (height ?to h0)) (height ?to h1)
      (not (stands ?o ?from h3)) (stands ?o ?to h1) (not (vacant ?to h1)) (vacant ?from h3)))
  ; 18 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-l0-l1-42
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l0 h1) (rests ?o h0) (place ?o on-spot) (beneath l1 h0)
      (height l0 h1) (height l1 h1-end) (height l2 h0) (vacant l1 h1))
    :effect (and (not (beneath l1 h0)) (not (at ?o l0)) (at ?o l1) (beneath l0 h0) (beneath l2 h0)
      (bit-0 ?o) (bit-5 ?o) (not (height l0 h1)) (height l0 h1-end) (not (height l1 h1-end)) (height l1 h1)
      (not (height l2 h0)) (height l2 h1-end) (not (stands ?o l0 h1)) (stands ?o l1 h1) (not (vacant l1 h1))
      (vacant l0 h1)))
  ; 6 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-l0-l1-43
    :parameters (?o - stick ?top_l2 - layer)
    :precondition (and (hand-empty) (stands ?o l0 h1) (rests ?o h0) (place ?o on-spot) (beneath l1 h0)
      (height l0 h1) (height l1 h1-end) (same-level ?top_l2 h2) (height l2 ?top_l2) (vacant l1 h3))
    :effect (and (not (beneath l1 h0)) (not (at ?o l0)) (at ?o l1) (beneath l0 h0) (beneath l2 h2)
      (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (bit-5 ?o) (not (height l0 h1)) (height l0 h3-end)
      (not (height l1 h1-end)) (height l1 h3) (not (height l2 ?top_l2)) (height l2 h3-end)
      (not (stands ?o l0 h1)) (stands ?o l1 h3) (not (vacant l1 h3)) (vacant l0 h1)))
  ; one move at 2 pairs of locations (pair-move-0 lists them): pick-release-stick-l0-l2-44, 31 moves: a stick lands on its release location at level 1; pick-release-stick-l2-l0-62, 23 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-0
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-0 ?from ?to ?n1) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (beneath ?n1 h0) (height ?from h1) (height ?n1 h1-end) (height ?to h0)
      (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (bit-0 ?o) (bit-5 ?o) (not (height ?from h1))
      (height ?from h0) (not (height ?to h0)) (height ?to h1) (not (stands ?o ?from h1)) (stands ?o ?to h1)
      (not (vacant ?to h1)) (vacant ?from h1)))
  ; one move at 2 pairs of locations (pair-move-1 lists them): pick-release-stick-l0-l2-45, 7 moves: a stick lands on its release location at level 1; pick-release-stick-l2-l0-63, 6 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-1
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-1 ?from ?to ?n1) (stands ?o ?from h3) (rests ?o h2)
      (place ?o on-spot) (beneath ?n1 h0) (height ?from h3) (height ?n1 h3-end) (height ?to h0)
      (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h2)) (rests ?o h0)
      (not (level ?o h3)) (level ?o h1) (bit-0 ?o) (bit-5 ?o) (not (height ?from h3)) (height ?from h2)
      (not (height ?n1 h3-end)) (height ?n1 h1-end) (not (height ?to h0)) (height ?to h1)
      (not (stands ?o ?from h3)) (stands ?o ?to h1) (not (vacant ?to h1)) (vacant ?from h3)))
  ; one move at 6 pairs of locations (pair-move-2 lists them): pick-release-stick-l0-l3-46, 11 moves: a stick lands on its release location at level 1; pick-release-stick-l0-l4-49, 14 moves: a stick lands on its release location at level 1; pick-release-stick-l0-l5-51, 14 moves: a stick lands on its release location at level 1; pick-release-stick-l2-l3-66, 13 moves: a stick lands on its release location at level 1; pick-release-stick-l2-l4-69, 13 moves: a stick lands on its release location at level 1; pick-release-stick-l2-l5-73, 25 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-2
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-2 ?from ?to ?n1) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (beneath ?n1 h0) (height ?from h1) (height ?n1 h1-end) (height ?to h0)
      (vacant ?to h1))
    :effect (and (not (beneath ?n1 h0)) (not (at ?o ?from)) (at ?o ?to) (not (bit-0 ?o)) (bit-5 ?o)
      (not (height ?from h1)) (height ?from h0) (not (height ?n1 h1-end)) (height ?n1 h0)
      (not (height ?to h0)) (height ?to h1) (not (stands ?o ?from h1)) (stands ?o ?to h1)
      (not (vacant ?to h1)) (vacant ?from h1)))
  ; one move at 5 pairs of locations (pair-move-3 lists them): pick-release-stick-l0-l3-47, 8 moves: a stick lands on its release location at level 3; pick-release-stick-l0-l4-50, 10 moves: a stick lands on its release location at level 3; pick-release-stick-l0-l5-52, 6 moves: a stick lands on its release location at level 3; pick-release-stick-l2-l3-67, 10 moves: a stick lands on its release location at level 3; pick-release-stick-l2-l4-71, 14 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-3
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-3 ?from ?to ?n1) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (beneath ?n1 h0) (height ?from h1) (height ?n1 h1-end) (height ?to h2)
      (vacant ?to h3))
    :effect (and (not (beneath ?n1 h0)) (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h0))
      (rests ?o h2) (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (not (bit-5 ?o))
      (not (height ?from h1)) (height ?from h0) (not (height ?n1 h1-end)) (height ?n1 h0)
      (not (height ?to h2)) (height ?to h3) (not (stands ?o ?from h1)) (stands ?o ?to h3)
      (not (vacant ?to h3)) (vacant ?from h1)))
  ; 8 moves: a stick ends off its release location at level 1
  (:action pick-release-stick-l0-l3-48
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l0 h1) (rests ?o h0) (place ?o minus-y-far) (height l0 h1)
      (height l3 h0) (vacant l3 h1))
    :effect (and (not (at ?o l0)) (at ?o l3) (not (place ?o minus-y-far)) (place ?o minus-y-mid)
      (not (bit-0 ?o)) (bit-5 ?o) (not (height l0 h1)) (height l0 h0) (not (height l3 h0)) (height l3 h1)
      (not (stands ?o l0 h1)) (stands ?o l3 h1) (not (vacant l3 h1)) (vacant l0 h1)))
  ; 21 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-l1-l0-53
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l1 h1) (rests ?o h0) (place ?o on-spot) (beneath l0 h0)
      (beneath l2 h0) (height l1 h1) (height l0 h1-end) (height l2 h1-end) (vacant l0 h1))
    :effect (and (not (beneath l0 h0)) (not (beneath l2 h0)) (not (at ?o l1)) (at ?o l0)
      (beneath l1 h0) (bit-0 ?o) (bit-5 ?o) (not (height l1 h1)) (height l1 h1-end) (not (height l0 h1-end))
      (height l0 h1) (not (height l2 h1-end)) (height l2 h0) (not (stands ?o l1 h1)) (stands ?o l0 h1)
      (not (vacant l0 h1)) (vacant l1 h1)))
  ; 6 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-l1-l0-54
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l1 h3) (rests ?o h0) (place ?o on-spot) (beneath l0 h0)
      (beneath l2 h2) (height l1 h3) (height l0 h3-end) (height l2 h3-end) (vacant l0 h1))
    :effect (and (not (beneath l0 h0)) (not (beneath l2 h2)) (not (at ?o l1)) (at ?o l0)
      (beneath l1 h0) (not (level ?o h3)) (level ?o h1) (bit-0 ?o) (bit-5 ?o) (not (height l1 h3))
      (height l1 h1-end) (not (height l0 h3-end)) (height l0 h1) (not (height l2 h3-end)) (height l2 h2)
      (not (stands ?o l1 h3)) (stands ?o l0 h1) (not (vacant l0 h1)) (vacant l1 h3)))
  ; 25 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-l1-l2-55
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l1 h1) (rests ?o h0) (place ?o on-spot) (beneath l0 h0)
      (beneath l2 h0) (height l1 h1) (height l0 h1-end) (height l2 h1-end) (vacant l2 h1))
    :effect (and (not (beneath l0 h0)) (not (beneath l2 h0)) (not (at ?o l1)) (at ?o l2)
      (beneath l1 h0) (bit-0 ?o) (bit-5 ?o) (not (height l1 h1)) (height l1 h1-end) (not (height l0 h1-end))
      (height l0 h0) (not (height l2 h1-end)) (height l2 h1) (not (stands ?o l1 h1)) (stands ?o l2 h1)
      (not (vacant l2 h1)) (vacant l1 h1)))
  ; one move at 3 pairs of locations (pair-move-4 lists them): pick-release-stick-l1-l3-56, 11 moves: a stick lands on its release location at level 1; pick-release-stick-l1-l4-58, 10 moves: a stick lands on its release location at level 1; pick-release-stick-l1-l5-59, 10 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-4
    :parameters (?o - stick ?from - location ?to - location ?n1 - location ?n2 - location)
    :precondition (and (hand-empty) (pair-move-4 ?from ?to ?n1 ?n2) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (beneath ?n1 h0) (beneath ?n2 h0) (height ?from h1) (height ?n1 h1-end)
      (height ?n2 h1-end) (height ?to h0) (vacant ?to h1))
    :effect (and (not (beneath ?n1 h0)) (not (beneath ?n2 h0)) (not (at ?o ?from)) (at ?o ?to)
      (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h1)) (height ?from h0) (not (height ?n1 h1-end))
      (height ?n1 h0) (not (height ?n2 h1-end)) (height ?n2 h0) (not (height ?to h0)) (height ?to h1)
      (not (stands ?o ?from h1)) (stands ?o ?to h1) (not (vacant ?to h1)) (vacant ?from h1)))
  ; one move at 2 pairs of locations (pair-move-5 lists them): pick-release-stick-l1-l3-57, 8 moves: a stick lands on its release location at level 3; pick-release-stick-l1-l5-60, 9 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-5
    :parameters (?o - stick ?from - location ?to - location ?n1 - location ?n2 - location)
    :precondition (and (hand-empty) (pair-move-5 ?from ?to ?n1 ?n2) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (beneath ?n1 h0) (beneath ?n2 h0) (height ?from h1) (height ?n1 h1-end)
      (height ?n2 h1-end) (height ?to h2) (vacant ?to h3))
    :effect (and (not (beneath ?n1 h0)) (not (beneath ?n2 h0)) (not (at ?o ?from)) (at ?o ?to)
      (not (rests ?o h0)) (rests ?o h2) (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (not (bit-5 ?o))
      (not (height ?from h1)) (height ?from h0) (not (height ?n1 h1-end)) (height ?n1 h0)
      (not (height ?n2 h1-end)) (height ?n2 h0) (not (height ?to h2)) (height ?to h3)
      (not (stands ?o ?from h1)) (stands ?o ?to h3) (not (vacant ?to h3)) (vacant ?from h1)))
  ; 7 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-l1-l5-61
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l1 h3) (rests ?o h0) (place ?o on-spot) (beneath l0 h0)
      (beneath l2 h2) (height l1 h3) (height l0 h3-end) (height l2 h3-end) (height l5 h0) (vacant l5 h1))
    :effect (and (not (beneath l0 h0)) (not (beneath l2 h2)) (not (at ?o l1)) (at ?o l5)
      (not (level ?o h3)) (level ?o h1) (not (bit-0 ?o)) (bit-5 ?o) (not (height l1 h3)) (height l1 h0)
      (not (height l0 h3-end)) (height l0 h0) (not (height l2 h3-end)) (height l2 h2) (not (height l5 h0))
      (height l5 h1) (not (stands ?o l1 h3)) (stands ?o l5 h1) (not (vacant l5 h1)) (vacant l1 h3)))
  ; 22 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-l2-l1-64
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l2 h1) (rests ?o h0) (place ?o on-spot) (beneath l1 h0)
      (height l2 h1) (height l1 h1-end) (height l0 h0) (vacant l1 h1))
    :effect (and (not (beneath l1 h0)) (not (at ?o l2)) (at ?o l1) (beneath l0 h0) (beneath l2 h0)
      (bit-0 ?o) (bit-5 ?o) (not (height l2 h1)) (height l2 h1-end) (not (height l1 h1-end)) (height l1 h1)
      (not (height l0 h0)) (height l0 h1-end) (not (stands ?o l2 h1)) (stands ?o l1 h1) (not (vacant l1 h1))
      (vacant l2 h1)))
  ; 6 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-l2-l1-65
    :parameters (?o - stick ?r0 - block)
    :precondition (and (hand-empty) (stands ?o l2 h1) (rests ?o h0) (place ?o on-spot) (stands ?r0 l1 h3)
      (rests ?r0 h1-end) (place ?r0 on-spot) (beneath l1 h0) (height l2 h1) (height l1 h3) (height l0 h0)
      (vacant l0 h3) (vacant l1 h1))
    :effect (and (not (beneath l1 h0)) (not (at ?o l2)) (at ?o l1) (beneath l0 h0) (beneath l2 h0)
      (bit-0 ?o) (bit-5 ?o) (not (at ?r0 l1)) (at ?r0 l0) (bit-0 ?r0) (not (bit-5 ?r0)) (not (height l2 h1))
      (height l2 h1-end) (not (height l1 h3)) (height l1 h1) (not (height l0 h0)) (height l0 h3)
      (not (stands ?o l2 h1)) (stands ?o l1 h1) (not (stands ?r0 l1 h3)) (stands ?r0 l0 h3)
      (not (vacant l0 h3)) (not (vacant l1 h1)) (vacant l1 h3) (vacant l2 h1)))
  ; one move at 2 pairs of locations (pair-move-6 lists them): pick-release-stick-l2-l3-68, 8 moves: a stick lands on its release location at level 1; pick-release-stick-l2-l5-74, 6 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-6
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-6 ?from ?to ?n1) (stands ?o ?from h3) (rests ?o h0)
      (place ?o on-spot) (beneath ?n1 h2) (height ?from h3) (height ?n1 h3-end) (height ?to h0)
      (vacant ?to h1))
    :effect (and (not (beneath ?n1 h2)) (not (at ?o ?from)) (at ?o ?to) (not (level ?o h3))
      (level ?o h1) (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h3)) (height ?from h0)
      (not (height ?n1 h3-end)) (height ?n1 h2) (not (height ?to h0)) (height ?to h1)
      (not (stands ?o ?from h3)) (stands ?o ?to h1) (not (vacant ?to h1)) (vacant ?from h3)))
  ; 7 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-l2-l4-70
    :parameters (?o - stick ?r0 - block)
    :precondition (and (hand-empty) (stands ?o l2 h1) (rests ?o h0) (place ?o on-spot) (stands ?r0 l1 h3)
      (rests ?r0 h1-end) (place ?r0 on-spot) (beneath l1 h0) (height l2 h1) (height l1 h3) (height l4 h0)
      (vacant l3 h3) (vacant l4 h1))
    :effect (and (not (beneath l1 h0)) (not (at ?o l2)) (at ?o l4) (not (bit-0 ?o)) (bit-5 ?o)
      (not (rests ?r0 h1-end)) (rests ?r0 h0) (not (at ?r0 l1)) (at ?r0 l3) (not (place ?r0 on-spot))
      (place ?r0 plus-y-mid) (not (bit-0 ?r0)) (not (bit-5 ?r0)) (not (height l2 h1)) (height l2 h0)
      (not (height l1 h3)) (height l1 h0) (not (height l4 h0)) (height l4 h1) (not (stands ?o l2 h1))
      (stands ?o l4 h1) (not (stands ?r0 l1 h3)) (stands ?r0 l3 h3) (not (vacant l3 h3)) (not (vacant l4 h1))
      (vacant l1 h3) (vacant l2 h1)))
  ; one move at 2 pairs of locations (pair-move-7 lists them): pick-release-stick-l2-l4-72, 14 moves: a stick ends off its release location at level 1; pick-release-stick-l2-l5-75, 6 moves: a stick ends off its release location at level 1
  (:action pick-release-stick-far-7
    :parameters (?o - stick ?from - location ?to - location)
    :precondition (and (hand-empty) (pair-move-7 ?from ?to) (stands ?o ?from h1) (rests ?o h0)
      (place ?o plus-y-mid) (height ?from h1) (height ?to h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h1))
      (height ?from h0) (not (height ?to h0)) (height ?to h1) (not (stands ?o ?from h1)) (stands ?o ?to h1)
      (not (vacant ?to h1)) (vacant ?from h1)))
  ; one move at 6 pairs of locations (pair-move-8 lists them): pick-release-stick-l3-l0-76, 80 moves: a stick lands on its release location at level 1; pick-release-stick-l3-l2-86, 69 moves: a stick lands on its release location at level 1; pick-release-stick-l4-l0-91, 65 moves: a stick lands on its release location at level 1; pick-release-stick-l4-l2-104, 53 moves: a stick lands on its release location at level 1; pick-release-stick-l5-l0-109, 58 moves: a stick lands on its release location at level 1; pick-release-stick-l5-l2-120, 63 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-8
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-8 ?from ?to ?n1) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (height ?from h1) (height ?to h0) (height ?n1 h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (beneath ?n1 h0) (bit-0 ?o) (bit-5 ?o)
      (not (height ?from h1)) (height ?from h0) (not (height ?to h0)) (height ?to h1) (not (height ?n1 h0))
      (height ?n1 h1-end) (not (stands ?o ?from h1)) (stands ?o ?to h1) (not (vacant ?to h1))
      (vacant ?from h1)))
  ; one move at 6 pairs of locations (pair-move-9 lists them): pick-release-stick-l3-l0-77, 13 moves: a stick lands on its release location at level 3; pick-release-stick-l3-l2-87, 15 moves: a stick lands on its release location at level 3; pick-release-stick-l4-l0-92, 10 moves: a stick lands on its release location at level 3; pick-release-stick-l4-l2-105, 10 moves: a stick lands on its release location at level 3; pick-release-stick-l5-l0-110, 12 moves: a stick lands on its release location at level 3; pick-release-stick-l5-l2-121, 11 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-9
    :parameters (?o - stick ?from - location ?to - location ?top_l1 - layer ?n1 - location)
    :precondition (and (hand-empty) (pair-move-9 ?from ?to ?n1) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (height ?from h1) (height ?to h0) (same-level ?top_l1 h2) (height ?n1 ?top_l1)
      (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (beneath ?n1 h2) (not (level ?o h1)) (level ?o h3)
      (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h1)) (height ?from h0) (not (height ?to h0))
      (height ?to h3) (not (height ?n1 ?top_l1)) (height ?n1 h3-end) (not (stands ?o ?from h1))
      (stands ?o ?to h3) (not (vacant ?to h3)) (vacant ?from h1)))
  ; one move at 6 pairs of locations (pair-move-10 lists them): pick-release-stick-l3-l0-78, 17 moves: a stick lands on its release location at level 3; pick-release-stick-l3-l2-88, 12 moves: a stick lands on its release location at level 3; pick-release-stick-l4-l0-93, 18 moves: a stick lands on its release location at level 3; pick-release-stick-l4-l2-106, 19 moves: a stick lands on its release location at level 3; pick-release-stick-l5-l0-111, 17 moves: a stick lands on its release location at level 3; pick-release-stick-l5-l2-122, 14 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-10
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-10 ?from ?to ?n1) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (height ?from h1) (height ?to h2) (height ?n1 h0) (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h0)) (rests ?o h2) (beneath ?n1 h0)
      (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height ?from h1))
      (height ?from h0) (not (height ?to h2)) (height ?to h3) (not (height ?n1 h0)) (height ?n1 h3-end)
      (not (stands ?o ?from h1)) (stands ?o ?to h3) (not (vacant ?to h3)) (vacant ?from h1)))
  ; one move at 6 pairs of locations (pair-move-11 lists them): pick-release-stick-l3-l0-79, 21 moves: a stick lands on its release location at level 1; pick-release-stick-l3-l2-90, 17 moves: a stick lands on its release location at level 1; pick-release-stick-l4-l0-94, 21 moves: a stick lands on its release location at level 1; pick-release-stick-l4-l2-108, 19 moves: a stick lands on its release location at level 1; pick-release-stick-l5-l0-113, 25 moves: a stick lands on its release location at level 1; pick-release-stick-l5-l2-125, 19 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-11
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-11 ?from ?to ?n1) (stands ?o ?from h3) (rests ?o h2)
      (place ?o on-spot) (height ?from h3) (height ?to h0) (height ?n1 h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h2)) (rests ?o h0) (beneath ?n1 h0)
      (not (level ?o h3)) (level ?o h1) (bit-0 ?o) (bit-5 ?o) (not (height ?from h3)) (height ?from h2)
      (not (height ?to h0)) (height ?to h1) (not (height ?n1 h0)) (height ?n1 h1-end)
      (not (stands ?o ?from h3)) (stands ?o ?to h1) (not (vacant ?to h1)) (vacant ?from h3)))
  ; one move at 2 pairs of locations (pair-move-12 lists them): pick-release-stick-l3-l0-80, 9 moves: a stick lands on its release location at level 3; pick-release-stick-l4-l0-95, 7 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-12
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-12 ?from ?to ?n1) (stands ?o ?from h3) (rests ?o h2)
      (place ?o on-spot) (height ?from h3) (height ?to h2) (height ?n1 h0) (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (beneath ?n1 h0) (not (bit-0 ?o)) (not (bit-5 ?o))
      (not (height ?from h3)) (height ?from h2) (not (height ?to h2)) (height ?to h3) (not (height ?n1 h0))
      (height ?n1 h3-end) (not (stands ?o ?from h3)) (stands ?o ?to h3) (not (vacant ?to h3))
      (vacant ?from h3)))
  ; one move at 3 pairs of locations (pair-move-13 lists them): pick-release-stick-l3-l1-81, 51 moves: a stick lands on its release location at level 1; pick-release-stick-l4-l1-96, 56 moves: a stick lands on its release location at level 1; pick-release-stick-l5-l1-114, 51 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-13
    :parameters (?o - stick ?from - location ?to - location ?n1 - location ?n2 - location)
    :precondition (and (hand-empty) (pair-move-13 ?from ?to ?n1 ?n2) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (height ?from h1) (height ?to h0) (height ?n1 h0) (height ?n2 h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (beneath ?n1 h0) (beneath ?n2 h0) (bit-0 ?o)
      (bit-5 ?o) (not (height ?from h1)) (height ?from h0) (not (height ?to h0)) (height ?to h1)
      (not (height ?n1 h0)) (height ?n1 h1-end) (not (height ?n2 h0)) (height ?n2 h1-end)
      (not (stands ?o ?from h1)) (stands ?o ?to h1) (not (vacant ?to h1)) (vacant ?from h1)))
  ; one move at 3 pairs of locations (pair-move-14 lists them): pick-release-stick-l3-l1-82, 15 moves: a stick lands on its release location at level 3; pick-release-stick-l4-l1-97, 17 moves: a stick lands on its release location at level 3; pick-release-stick-l5-l1-115, 10 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-14
    :parameters (?o - stick ?from - location ?to - location ?top_l2 - layer ?n1 - location ?n2 - location)
    :precondition (and (hand-empty) (pair-move-14 ?from ?to ?n1 ?n2) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (height ?from h1) (height ?to h0) (height ?n1 h0) (same-level ?top_l2 h2)
      (height ?n2 ?top_l2) (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (beneath ?n1 h0) (beneath ?n2 h2)
      (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h1)) (height ?from h0)
      (not (height ?to h0)) (height ?to h3) (not (height ?n1 h0)) (height ?n1 h3-end)
      (not (height ?n2 ?top_l2)) (height ?n2 h3-end) (not (stands ?o ?from h1)) (stands ?o ?to h3)
      (not (vacant ?to h3)) (vacant ?from h1)))
  ; one move at 3 pairs of locations (pair-move-15 lists them): pick-release-stick-l3-l1-83, 11 moves: a stick lands on its release location at level 3; pick-release-stick-l4-l1-98, 8 moves: a stick lands on its release location at level 3; pick-release-stick-l5-l1-116, 9 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-15
    :parameters (?o - stick ?from - location ?to - location ?top_l0 - layer ?n1 - location ?n2 - location)
    :precondition (and (hand-empty) (pair-move-15 ?from ?to ?n1 ?n2) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (height ?from h1) (height ?to h0) (same-level ?top_l0 h2) (height ?n1 ?top_l0)
      (height ?n2 h0) (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (beneath ?n1 h2) (beneath ?n2 h0)
      (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h1)) (height ?from h0)
      (not (height ?to h0)) (height ?to h3) (not (height ?n1 ?top_l0)) (height ?n1 h3-end)
      (not (height ?n2 h0)) (height ?n2 h3-end) (not (stands ?o ?from h1)) (stands ?o ?to h3)
      (not (vacant ?to h3)) (vacant ?from h1)))
  ; one move at 3 pairs of locations (pair-move-16 lists them): pick-release-stick-l3-l1-84, 13 moves: a stick lands on its release location at level 3; pick-release-stick-l4-l1-99, 9 moves: a stick lands on its release location at level 3; pick-release-stick-l5-l1-117, 17 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-16
    :parameters (?o - stick ?from - location ?to - location ?n1 - location ?n2 - location)
    :precondition (and (hand-empty) (pair-move-16 ?from ?to ?n1 ?n2) (stands ?o ?from h1) (rests ?o h0)
      (place ?o on-spot) (height ?from h1) (height ?to h2) (height ?n1 h0) (height ?n2 h0) (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h0)) (rests ?o h2) (beneath ?n1 h0)
      (beneath ?n2 h0) (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (not (bit-5 ?o))
      (not (height ?from h1)) (height ?from h0) (not (height ?to h2)) (height ?to h3) (not (height ?n1 h0))
      (height ?n1 h3-end) (not (height ?n2 h0)) (height ?n2 h3-end) (not (stands ?o ?from h1))
      (stands ?o ?to h3) (not (vacant ?to h3)) (vacant ?from h1)))
  ; one move at 3 pairs of locations (pair-move-17 lists them): pick-release-stick-l3-l1-85, 12 moves: a stick lands on its release location at level 1; pick-release-stick-l4-l1-101, 14 moves: a stick lands on its release location at level 1; pick-release-stick-l5-l1-118, 10 moves: a stick lands on its release location at level 1
  (:action pick-release-stick-far-17
    :parameters (?o - stick ?from - location ?to - location ?n1 - location ?n2 - location)
    :precondition (and (hand-empty) (pair-move-17 ?from ?to ?n1 ?n2) (stands ?o ?from h3) (rests ?o h2)
      (place ?o on-spot) (height ?from h3) (height ?to h0) (height ?n1 h0) (height ?n2 h0) (vacant ?to h1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h2)) (rests ?o h0) (beneath ?n1 h0)
      (beneath ?n2 h0) (not (level ?o h3)) (level ?o h1) (bit-0 ?o) (bit-5 ?o) (not (height ?from h3))
      (height ?from h2) (not (height ?to h0)) (height ?to h1) (not (height ?n1 h0)) (height ?n1 h1-end)
      (not (height ?n2 h0)) (height ?n2 h1-end) (not (stands ?o ?from h3)) (stands ?o ?to h1)
      (not (vacant ?to h1)) (vacant ?from h3)))
  ; 7 moves: a stick lands on its release location at level 5
  (:action pick-release-stick-l3-l2-89
    :parameters (?o - stick ?v - block)
    :precondition (and (hand-empty) (stands ?o l3 h1) (rests ?o h0) (place ?o on-spot) (height l3 h1)
      (height l2 h4) (height l1 h0) (stands ?v l2 h4) (vacant l2 h5))
    :effect (and (not (at ?o l3)) (at ?o l2) (not (rests ?o h0)) (rests ?o h4) (beneath l1 h0)
      (not (level ?o h1)) (level ?o h5) (not (bit-0 ?o)) (not (bit-5 ?o)) (bit-0 ?v) (bit-5 ?v)
      (not (height l3 h1)) (height l3 h0) (not (height l2 h4)) (height l2 h5) (not (height l1 h0))
      (height l1 h5-end) (not (stands ?o l3 h1)) (stands ?o l2 h5) (not (vacant l2 h5)) (vacant l3 h1)))
  ; 8 moves: a stick lands on its release location at level 2
  (:action pick-release-stick-l4-l1-100
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l4 h3) (rests ?o h1) (place ?o on-spot) (height l4 h3)
      (height l1 h0) (height l0 h0) (height l2 h0) (vacant l1 h2))
    :effect (and (not (at ?o l4)) (at ?o l1) (not (rests ?o h1)) (rests ?o h0) (beneath l0 h0)
      (beneath l2 h0) (not (level ?o h3)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height l4 h3))
      (height l4 h1) (not (height l1 h0)) (height l1 h2) (not (height l0 h0)) (height l0 h2-end)
      (not (height l2 h0)) (height l2 h2-end) (not (stands ?o l4 h3)) (stands ?o l1 h2) (not (vacant l1 h2))
      (vacant l4 h3)))
  ; one move at 2 pairs of locations (pair-move-18 lists them): pick-release-stick-l4-l1-102, 8 moves: a stick lands on its release location at level 3; pick-release-stick-l5-l1-119, 6 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-far-18
    :parameters (?o - stick ?from - location ?to - location ?top_l2 - layer ?n1 - location ?n2 - location)
    :precondition (and (hand-empty) (pair-move-18 ?from ?to ?n1 ?n2) (stands ?o ?from h3) (rests ?o h2)
      (place ?o on-spot) (height ?from h3) (height ?to h0) (height ?n1 h0) (same-level ?top_l2 h2)
      (height ?n2 ?top_l2) (vacant ?to h3))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h2)) (rests ?o h0) (beneath ?n1 h0)
      (beneath ?n2 h2) (not (bit-0 ?o)) (bit-5 ?o) (not (height ?from h3)) (height ?from h2)
      (not (height ?to h0)) (height ?to h3) (not (height ?n1 h0)) (height ?n1 h3-end)
      (not (height ?n2 ?top_l2)) (height ?n2 h3-end) (not (stands ?o ?from h3)) (stands ?o ?to h3)
      (not (vacant ?to h3)) (vacant ?from h3)))
  ; 7 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-l4-l1-103
    :parameters (?o - stick ?top_l0 - layer)
    :precondition (and (hand-empty) (stands ?o l4 h3) (rests ?o h2) (place ?o on-spot) (height l4 h3)
      (height l1 h0) (same-level ?top_l0 h2) (height l0 ?top_l0) (height l2 h0) (vacant l1 h3))
    :effect (and (not (at ?o l4)) (at ?o l1) (not (rests ?o h2)) (rests ?o h0) (beneath l0 h2)
      (beneath l2 h0) (not (bit-0 ?o)) (bit-5 ?o) (not (height l4 h3)) (height l4 h2) (not (height l1 h0))
      (height l1 h3) (not (height l0 ?top_l0)) (height l0 h3-end) (not (height l2 h0)) (height l2 h3-end)
      (not (stands ?o l4 h3)) (stands ?o l1 h3) (not (vacant l1 h3)) (vacant l4 h3)))
  ; one move at 2 pairs of locations (pair-move-19 lists them): pick-release-stick-l4-l2-107, 10 moves: a stick lands on its release location at level 2; pick-release-stick-l5-l2-124, 11 moves: a stick lands on its release location at level 2
  (:action pick-release-stick-far-19
    :parameters (?o - stick ?from - location ?to - location ?n1 - location)
    :precondition (and (hand-empty) (pair-move-19 ?from ?to ?n1) (stands ?o ?from h3) (rests ?o h1)
      (place ?o on-spot) (height ?from h3) (height ?to h0) (height ?n1 h0) (vacant ?to h2))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (rests ?o h1)) (rests ?o h0) (beneath ?n1 h0)
      (not (level ?o h3)) (level ?o h2) (bit-0 ?o) (bit-5 ?o) (not (height ?from h3)) (height ?from h1)
      (not (height ?to h0)) (height ?to h2) (not (height ?n1 h0)) (height ?n1 h2-end)
      (not (stands ?o ?from h3)) (stands ?o ?to h2) (not (vacant ?to h2)) (vacant ?from h3)))
  ; 6 moves: a stick lands on its release location at level 2
  (:action pick-release-stick-l5-l0-112
    :parameters (?o - stick)
    :precondition (and (hand-empty) (stands ?o l5 h3) (rests ?o h1) (place ?o on-spot) (height l5 h3)
      (height l0 h0) (height l1 h0) (vacant l0 h2))
    :effect (and (not (at ?o l5)) (at ?o l0) (not (rests ?o h1)) (rests ?o h0) (beneath l1 h0)
      (not (level ?o h3)) (level ?o h2) (bit-0 ?o) (not (bit-5 ?o)) (not (height l5 h3)) (height l5 h1)
      (not (height l0 h0)) (height l0 h2) (not (height l1 h0)) (height l1 h2-end) (not (stands ?o l5 h3))
      (stands ?o l0 h2) (not (vacant l0 h2)) (vacant l5 h3)))
  ; 10 moves: a stick lands on its release location at level 3
  (:action pick-release-stick-l5-l2-123
    :parameters (?o - stick ?top_l1 - layer)
    :precondition (and (hand-empty) (stands ?o l5 h1) (rests ?o h0) (place ?o on-spot) (height l5 h1)
      (height l2 h2) (same-level ?top_l1 h2) (height l1 ?top_l1) (vacant l2 h3))
    :effect (and (not (at ?o l5)) (at ?o l2) (not (rests ?o h0)) (rests ?o h2) (beneath l1 h2)
      (not (level ?o h1)) (level ?o h3) (not (bit-0 ?o)) (not (bit-5 ?o)) (not (height l5 h1)) (height l5 h0)
      (not (height l2 h2)) (height l2 h3) (not (height l1 ?top_l1)) (height l1 h3-end) (not (stands ?o l5 h1))
      (stands ?o l2 h3) (not (vacant l2 h3)) (vacant l5 h1)))
)
