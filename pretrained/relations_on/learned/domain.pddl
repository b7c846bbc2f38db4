(define (domain learned-relations)
  (:requirements :strips :typing :equality)
  (:types item location)
  (:constants l0 l1 l2 l3 l4 l5 - location)
  (:predicates
    (at ?x0 - item ?x1 - location)
    (clear ?x0 - item)
    (empty ?x0 - location)
    (on ?x0 - item ?x1 - item)
    (on-table ?x0 - item)
    (u0 ?x0 - item)
    (u1 ?x0 - item)
    (u2 ?x0 - item)
    (u4 ?x0 - item)
    (u5 ?x0 - item)
    (u7 ?x0 - item)
  )
  (:action move-0  ; seen 4769 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (clear ?o1) (empty ?to) (on-table ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to))))
  (:action move-1  ; seen 2107 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (clear ?o2) (on-table ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-2  ; seen 1852 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (clear ?o1) (empty ?to) (on ?o1 ?o2) (u4 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (clear ?o2) (on-table ?o1) (not (at ?o1 ?from)) (not (empty ?to)) (not (on ?o1 ?o2))))
  (:action move-3  ; seen 485 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o3 ?to) (clear ?o1) (clear ?o3) (on ?o1 ?o2) (u4 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?to) (clear ?o2) (on ?o1 ?o3) (not (at ?o1 ?from)) (not (clear ?o3)) (not (on ?o1 ?o2))))
  (:action move-4  ; seen 356 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (empty ?to) (empty l1) (on-table ?o1) (u1 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 l1) (empty ?from) (not (at ?o1 ?from)) (not (empty l1))))
  (:action move-9  ; seen 100 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (clear ?o2) (empty l1) (on-table ?o1) (u0 ?o1) (u2 ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 l1) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty l1)) (not (on-table ?o1))))
  (:action move-12  ; seen 78 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l1) (clear ?o1) (empty ?from) (empty ?to) (u0 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty l1) (not (at ?o1 l1)) (not (empty ?to))))
  (:action move-15  ; seen 64 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 l0) (clear ?o1) (empty ?from) (empty ?to) (on-table ?o1) (u5 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty l0) (not (at ?o1 l0)) (not (empty ?to))))
  (:action move-20  ; seen 42 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 l1) (at ?o2 ?to) (clear ?o1) (empty ?from) (u0 ?o1) (u1 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty l1) (on ?o1 ?o2) (not (at ?o1 l1)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-22  ; seen 39 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (empty l0) (u0 ?o1) (u5 ?o2) (u7 ?o1) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 l0) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty l0)) (not (on-table ?o1))))
)
