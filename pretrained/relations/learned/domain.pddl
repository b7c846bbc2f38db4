(define (domain learned-relations)
  (:requirements :strips :typing :equality)
  (:types item location)
  (:constants l0 l1 l2 l3 l4 l5 - location)
  (:predicates
    (at ?x0 - item ?x1 - location)
    (empty ?x0 - location)
    (u0 ?x0 - item)
    (u1 ?x0 - item)
    (u6 ?x0 - item)
  )
  (:action move-0  ; seen 5456 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty ?to) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to))))
  (:action move-1  ; seen 2630 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (not (at ?o1 ?from))))
  (:action move-2  ; seen 2275 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty ?to) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (not (at ?o1 ?from)) (not (empty ?to))))
  (:action move-3  ; seen 646 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (not (at ?o1 ?from))))
  (:action move-4  ; seen 336 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty l1) (not (= ?from ?to)))
    :effect (and (at ?o1 l1) (empty ?from) (not (at ?o1 ?from)) (not (empty l1))))
  (:action move-5  ; seen 152 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l1) (empty ?to) (u0 ?o1) (u1 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty l1) (not (at ?o1 l1)) (not (empty ?to))))
  (:action move-6  ; seen 145 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty l1) (not (= ?from ?to)))
    :effect (and (at ?o1 l1) (not (at ?o1 ?from)) (not (empty l1))))
  (:action move-7  ; seen 84 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty l0) (not (= ?from ?to)))
    :effect (and (at ?o1 l0) (empty ?from) (not (at ?o1 ?from)) (not (empty l0))))
  (:action move-8  ; seen 81 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?from) (empty ?to) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (empty ?from) (not (at ?o1 ?from)) (not (at ?o2 ?from)) (not (empty ?to))))
  (:action move-9  ; seen 80 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l1) (u0 ?o1) (u1 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty l1) (not (at ?o1 l1))))
  (:action move-10  ; seen 80 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (not (= ?from ?to)))
    :effect (and (at ?o1 l1) (empty ?from) (not (at ?o1 ?from))))
  (:action move-11  ; seen 70 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (empty l0) (u0 ?o2) (u1 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 l0) (empty ?from) (not (at ?o1 ?from)) (not (at ?o2 ?to)) (not (empty l0))))
  (:action move-12  ; seen 63 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?to) (at ?o2 ?from) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?from) (at ?o2 ?to) (not (at ?o1 ?to)) (not (at ?o2 ?from))))
  (:action move-13  ; seen 58 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (empty l1) (u0 ?o2) (u1 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 l1) (empty ?from) (not (at ?o1 ?from)) (not (at ?o2 ?to)) (not (empty l1))))
  (:action move-14  ; seen 56 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty l2) (not (= ?from ?to)))
    :effect (and (at ?o1 l2) (empty ?from) (not (at ?o1 ?from)) (not (empty l2))))
  (:action move-15  ; seen 46 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l2) (empty ?to) (u0 ?o1) (u1 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty l2) (not (at ?o1 l2)) (not (empty ?to))))
  (:action move-16  ; seen 45 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (not (= ?from ?to)))
    :effect (and (at ?o1 l2) (empty ?from) (not (at ?o1 ?from))))
  (:action move-17  ; seen 42 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty l2) (not (= ?from ?to)))
    :effect (and (at ?o1 l2) (not (at ?o1 ?from)) (not (empty l2))))
  (:action move-18  ; seen 39 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty l4) (not (= ?from ?to)))
    :effect (and (at ?o1 l4) (empty ?from) (not (at ?o1 ?from)) (not (empty l4))))
  (:action move-19  ; seen 39 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty l0) (not (= ?from ?to)))
    :effect (and (at ?o1 l0) (not (at ?o1 ?from)) (not (empty l0))))
  (:action move-20  ; seen 36 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l2) (u0 ?o1) (u1 ?o1) (u6 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty l2) (not (at ?o1 l2))))
  (:action move-21  ; seen 35 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 l0) (at ?o2 ?from) (empty ?to) (u0 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?from) (at ?o2 ?to) (empty l0) (not (at ?o1 l0)) (not (at ?o2 ?from)) (not (empty ?to))))
  (:action move-22  ; seen 35 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l2) (empty ?to) (u0 ?o1) (u1 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (not (at ?o1 l2)) (not (empty ?to))))
  (:action move-23  ; seen 31 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (not (= ?from ?to)))
    :effect (and (at ?o1 l4) (empty ?from) (not (at ?o1 ?from))))
  (:action move-24  ; seen 30 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?from) (empty ?to) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (not (at ?o1 ?from)) (not (at ?o2 ?from)) (not (empty ?to))))
  (:action move-25  ; seen 30 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l1) (empty ?to) (u0 ?o1) (u1 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (not (at ?o1 l1)) (not (empty ?to))))
  (:action move-26  ; seen 28 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?from) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (empty ?from) (not (at ?o1 ?from)) (not (at ?o2 ?from))))
  (:action move-27  ; seen 26 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 l1) (empty ?to) (u0 ?o2) (u1 ?o2) (u6 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (empty ?from) (empty l1) (not (at ?o1 ?from)) (not (at ?o2 l1)) (not (empty ?to))))
  (:action move-28  ; seen 26 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 l1) (at ?o2 ?from) (empty ?to) (u0 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?from) (at ?o2 ?to) (empty l1) (not (at ?o1 l1)) (not (at ?o2 ?from)) (not (empty ?to))))
  (:action move-29  ; seen 25 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (not (= ?from ?to)))
    :effect (and (at ?o1 l0) (empty ?from) (not (at ?o1 ?from))))
  (:action move-30  ; seen 23 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (empty l2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 l2) (empty ?from) (not (at ?o1 ?from)) (not (at ?o2 ?to)) (not (empty l2))))
  (:action move-31  ; seen 23 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (empty l0) (u0 ?o2) (u1 ?o2) (u6 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 l0) (not (at ?o1 ?from)) (not (at ?o2 ?to)) (not (empty l0))))
  (:action move-32  ; seen 22 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l0) (empty ?to) (u0 ?o1) (u1 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty l0) (not (at ?o1 l0)) (not (empty ?to))))
  (:action move-33  ; seen 21 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?from) (empty ?to) (empty l1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 l1) (empty ?from) (not (at ?o1 ?from)) (not (at ?o2 ?from)) (not (empty ?to)) (not (empty l1))))
  (:action move-34  ; seen 20 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?to) (empty l2) (u0 ?o1) (u1 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 l2) (empty ?to) (not (at ?o1 ?to)) (not (empty l2))))
)
