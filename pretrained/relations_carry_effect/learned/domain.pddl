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
    (u3 ?x0 - item)
    (u4 ?x0 - item)
    (u5 ?x0 - item)
    (u6 ?x0 - item)
    (u7 ?x0 - item)
  )
  (:action move-0  ; seen 4996 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (clear ?o1) (empty ?to) (on-table ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to))))
  (:action move-1  ; seen 2124 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (clear ?o2) (on-table ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-2  ; seen 1781 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (clear ?o1) (empty ?to) (on ?o1 ?o2) (u2 ?o2) (u4 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (clear ?o2) (on-table ?o1) (not (at ?o1 ?from)) (not (empty ?to)) (not (on ?o1 ?o2))))
  (:action move-3  ; seen 470 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?from) (at ?o3 ?to) (clear ?o3) (on ?o1 ?o2) (u3 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?to) (clear ?o2) (on ?o1 ?o3) (not (at ?o1 ?from)) (not (clear ?o3)) (not (on ?o1 ?o2))))
  (:action move-4  ; seen 256 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o1 ?to) (clear ?o1) (on-table ?o1) (u5 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (empty ?from) (not (at ?o1 ?from))))
  (:action move-5  ; seen 243 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 l1) (at ?o2 ?from) (clear ?o2) (empty ?to) (on ?o2 ?o1) (on-table ?o1) (u5 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (on-table ?o2) (not (at ?o2 ?from)) (not (empty ?to)) (not (on ?o2 ?o1))))
  (:action move-6  ; seen 207 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l0) (at ?o1 ?from) (clear ?o1) (empty ?to) (empty l1) (on-table ?o1) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l1))))
  (:action move-7  ; seen 202 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (at ?o2 l1) (clear ?o1) (clear ?o2) (on-table ?o1) (u0 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o2 ?to)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-8  ; seen 201 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l2) (at ?o1 ?from) (clear ?o1) (empty ?to) (empty l1) (on-table ?o1) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l1))))
  (:action move-10  ; seen 163 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (clear ?o1) (empty ?to) (empty l0) (empty l2) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l0) (at ?o1 l2) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l0)) (not (empty l2))))
  (:action move-11  ; seen 116 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l0) (at ?o1 ?from) (at ?o1 l1) (clear ?o1) (empty ?to) (u0 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l1) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (empty ?to))))
  (:action move-13  ; seen 111 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l2) (at ?o1 ?from) (at ?o1 l1) (clear ?o1) (empty ?to) (on-table ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l1) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (empty ?to))))
  (:action move-15  ; seen 101 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o2 ?from) (at ?o2 l2) (clear ?o2) (empty ?to) (on ?o2 ?o1) (on-table ?o1) (u0 ?o1) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (on-table ?o2) (not (at ?o2 ?from)) (not (at ?o2 l2)) (not (empty ?to)) (not (on ?o2 ?o1))))
  (:action move-17  ; seen 95 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l0) (at ?o1 ?from) (at ?o2 ?from) (clear ?o1) (empty ?to) (empty l1) (on ?o1 ?o2) (u2 ?o2) (u3 ?o1) (u4 ?o2) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (clear ?o2) (on-table ?o1) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l1)) (not (on ?o1 ?o2))))
  (:action move-19  ; seen 94 times; carries ?o1 and ?o2 together
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l2) (at ?o1 ?from) (at ?o1 l1) (at ?o2 ?from) (empty ?to) (u0 ?o2) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (empty ?from) (empty l1) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (at ?o2 ?from)) (not (empty ?to))))
  (:action move-20  ; seen 92 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (at ?o2 ?from) (clear ?o1) (clear ?o3) (empty ?to) (on-table ?o3) (u2 ?o3) (u3 ?o2) (u6 ?o1) (u6 ?o2) (u7 ?o1) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?from) (at ?o2 ?to) (on ?o3 ?o1) (not (at ?o2 ?from)) (not (clear ?o1)) (not (empty ?to)) (not (on-table ?o3))))
  (:action move-21  ; seen 90 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (at ?o2 ?to) (at ?o2 l2) (clear ?o1) (clear ?o2) (on-table ?o1) (on-table ?o2) (u0 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l2) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o2 ?to)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-23  ; seen 83 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l2) (at ?o1 ?from) (at ?o2 ?from) (clear ?o1) (empty ?to) (empty l1) (on ?o1 ?o2) (u3 ?o1) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (clear ?o2) (on-table ?o1) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l1)) (not (on ?o1 ?o2))))
  (:action move-25  ; seen 79 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o1 l0) (at ?o2 ?from) (at ?o2 l0) (empty ?to) (on ?o2 ?o1) (u3 ?o2) (u5 ?o1) (u6 ?o2) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (on-table ?o2) (not (at ?o2 ?from)) (not (at ?o2 l0)) (not (empty ?to)) (not (on ?o2 ?o1))))
  (:action move-26  ; seen 75 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l0) (at ?o1 ?from) (at ?o1 l1) (at ?o2 ?to) (clear ?o1) (clear ?o2) (on-table ?o1) (u1 ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l1) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-28  ; seen 70 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l2) (at ?o1 ?from) (at ?o1 l1) (at ?o2 ?to) (clear ?o1) (clear ?o2) (on-table ?o1) (u1 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l1) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-30  ; seen 68 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (clear ?o1) (empty ?to) (empty l0) (empty l2) (on ?o1 ?o2) (u3 ?o1) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l0) (at ?o1 l2) (clear ?o2) (on-table ?o1) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l0)) (not (empty l2)) (not (on ?o1 ?o2))))
  (:action move-32  ; seen 65 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (at ?o2 ?to) (at ?o2 l0) (clear ?o1) (clear ?o2) (on-table ?o1) (on-table ?o2) (u5 ?o2) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l0) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o2 ?to)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-33  ; seen 65 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (at ?o1 l1) (at ?o3 ?from) (clear ?o2) (clear ?o3) (empty ?to) (on-table ?o1) (on-table ?o3) (u3 ?o1) (u5 ?o2) (u7 ?o1) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?from) (at ?o2 ?from) (at ?o3 ?to) (on ?o1 ?o2) (not (at ?o3 ?from)) (not (clear ?o2)) (not (empty ?to)) (not (on-table ?o1))))
  (:action move-35  ; seen 62 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l2) (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (clear ?o2) (empty l1) (on-table ?o1) (u0 ?o1) (u6 ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty l1)) (not (on-table ?o1))))
  (:action move-36  ; seen 61 times; carries ?o1 and ?o2 together
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l0) (at ?o1 ?from) (at ?o1 l1) (at ?o2 ?from) (empty ?to) (on-table ?o2) (u3 ?o1) (u5 ?o2) (u6 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (empty ?from) (empty l1) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (at ?o2 ?from)) (not (empty ?to))))
  (:action move-38  ; seen 57 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l0) (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (clear ?o2) (empty l1) (on-table ?o1) (u0 ?o1) (u3 ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty l1)) (not (on-table ?o1))))
  (:action move-39  ; seen 53 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?to) (at ?o2 ?from) (at ?o2 ?to) (empty l5) (on ?o2 ?o1) (u0 ?o1) (u5 ?o2) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?from) (not (at ?o1 ?to)) (not (at ?o2 ?from))))
  (:action move-41  ; seen 51 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o1 ?from) (at ?o1 l0) (at ?o1 l2) (clear ?o1) (empty ?to) (on-table ?o1) (u0 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l0) (empty l2) (not (at ?o1 ?from)) (not (at ?o1 l0)) (not (at ?o1 l2)) (not (empty ?to))))
  (:action move-49  ; seen 43 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (at ?o1 ?to) (clear ?o1) (empty l0) (on-table ?o1) (u5 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 l0) (not (empty l0))))
  (:action move-50  ; seen 43 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o1 ?from) (at ?o1 l0) (at ?o1 l2) (at ?o2 ?to) (clear ?o1) (clear ?o2) (on-table ?o1) (u1 ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l0) (empty l2) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o1 l0)) (not (at ?o1 l2)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-52  ; seen 40 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (at ?o1 ?to) (clear ?o1) (empty l2) (on-table ?o1) (u0 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 l2) (not (empty l2))))
  (:action move-54  ; seen 38 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l2) (at ?o1 ?from) (at ?o2 l1) (clear ?o1) (clear ?o2) (empty ?to) (on-table ?o1) (on-table ?o2) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (at ?o2 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty ?to)) (not (on-table ?o1))))
  (:action move-60  ; seen 35 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l0) (at ?o1 ?from) (at ?o2 l1) (clear ?o1) (clear ?o2) (empty ?to) (on-table ?o1) (on-table ?o2) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (at ?o2 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty ?to)) (not (on-table ?o1))))
  (:action move-62  ; seen 35 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (at ?o2 ?to) (at ?o3 ?from) (clear ?o1) (clear ?o2) (on-table ?o2) (on-table ?o3) (u2 ?o3) (u3 ?o2) (u3 ?o3) (u6 ?o1) (u6 ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?from) (at ?o1 ?to) (at ?o2 ?from) (at ?o3 ?to) (on ?o2 ?o1) (on ?o3 ?o2) (not (at ?o3 ?from)) (not (clear ?o1)) (not (clear ?o2)) (not (on-table ?o2)) (not (on-table ?o3))))
  (:action move-66  ; seen 32 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (clear ?o2) (empty l0) (empty l2) (on-table ?o1) (on-table ?o2) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l0) (at ?o1 l2) (at ?o2 l0) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty l0)) (not (empty l2)) (not (on-table ?o1))))
  (:action move-73  ; seen 28 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l1) (= ?to l4) (at ?o1 ?from) (at ?o1 l0) (clear ?o1) (empty ?to) (empty l3) (on-table ?o1) (u5 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l3) (empty ?from) (empty l0) (not (at ?o1 ?from)) (not (at ?o1 l0)) (not (empty ?to)) (not (empty l3))))
  (:action move-75  ; seen 28 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o2 ?from) (at ?o2 l2) (at ?o3 ?to) (clear ?o2) (clear ?o3) (on ?o2 ?o1) (on-table ?o1) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (on ?o2 ?o3) (not (at ?o2 ?from)) (not (at ?o2 l2)) (not (clear ?o3)) (not (on ?o2 ?o1))))
  (:action move-77  ; seen 28 times; carries ?o1 and ?o2 together
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o1 ?from) (at ?o1 l0) (at ?o2 l2) (empty ?to) (on ?o2 ?o1) (u0 ?o1) (u5 ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (empty ?from) (empty l0) (empty l2) (not (at ?o1 ?from)) (not (at ?o1 l0)) (not (at ?o2 l2)) (not (empty ?to))))
  (:action move-78  ; seen 28 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (= ?from l2) (at ?o1 ?from) (at ?o2 l1) (at ?o3 ?from) (empty ?to) (on ?o1 ?o2) (on-table ?o3) (u5 ?o1) (u5 ?o3) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?to) (clear ?o2) (on-table ?o1) (not (at ?o1 ?from)) (not (at ?o2 l1)) (not (at ?o3 ?from)) (not (empty ?to)) (not (on ?o1 ?o2))))
  (:action move-82  ; seen 26 times; carries ?o1 and ?o2 together
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o1 ?from) (at ?o1 l2) (at ?o2 l0) (clear ?o2) (empty ?to) (on ?o2 ?o1) (on-table ?o1) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (empty ?from) (empty l0) (empty l2) (not (at ?o1 ?from)) (not (at ?o1 l2)) (not (at ?o2 l0)) (not (empty ?to))))
  (:action move-84  ; seen 25 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l1) (= ?to l4) (at ?o1 ?from) (at ?o1 l2) (clear ?o1) (empty ?to) (empty l5) (on-table ?o1) (u0 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l5) (empty ?from) (empty l2) (not (at ?o1 ?from)) (not (at ?o1 l2)) (not (empty ?to)) (not (empty l5))))
  (:action move-91  ; seen 24 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o2 ?from) (at ?o2 ?to) (clear ?o2) (empty l2) (empty l4) (empty l5) (on ?o2 ?o1) (u6 ?o1) (u6 ?o2) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 l2) (not (at ?o2 ?from)) (not (at ?o2 ?to)) (not (empty l2))))
  (:action move-93  ; seen 23 times; carries ?o1 and ?o2 together
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (= ?to l4) (at ?o1 ?from) (at ?o2 l2) (empty ?to) (empty l5) (on ?o2 ?o1) (u0 ?o2) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l5) (at ?o2 ?to) (at ?o2 l5) (empty ?from) (empty l2) (not (at ?o1 ?from)) (not (at ?o2 l2)) (not (empty ?to)) (not (empty l5))))
  (:action move-96  ; seen 22 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (= ?to l2) (at ?o1 ?from) (at ?o2 l1) (clear ?o1) (clear ?o3) (on ?o3 ?o2) (on-table ?o1) (u0 ?o3) (u6 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?to) (at ?o2 ?to) (at ?o3 l1) (empty ?from) (on ?o1 ?o3) (not (at ?o1 ?from)) (not (clear ?o3)) (not (on-table ?o1))))
  (:action move-97  ; seen 22 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o1 ?from) (at ?o1 l2) (at ?o2 ?from) (empty ?to) (on ?o1 ?o2) (on-table ?o2) (u3 ?o1) (u5 ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (clear ?o2) (on-table ?o1) (not (at ?o1 ?from)) (not (at ?o1 l2)) (not (empty ?to)) (not (on ?o1 ?o2))))
  (:action move-98  ; seen 21 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o1 ?from) (at ?o1 l0) (at ?o2 ?to) (clear ?o1) (clear ?o2) (empty l2) (on-table ?o1) (on-table ?o2) (u3 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l0) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o1 l0)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-99  ; seen 21 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l1) (= ?to l5) (at ?o1 ?from) (at ?o1 l0) (clear ?o1) (empty ?to) (empty l4) (on-table ?o1) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l4) (empty ?from) (empty l0) (not (at ?o1 ?from)) (not (at ?o1 l0)) (not (empty ?to)) (not (empty l4))))
  (:action move-100  ; seen 21 times; carries ?o1 and ?o2 together
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l0) (= ?to l2) (at ?o1 ?from) (at ?o2 ?from) (at ?o2 l1) (clear ?o2) (empty ?to) (on ?o2 ?o1) (on-table ?o1) (u5 ?o1) (u6 ?o2) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (at ?o2 ?to) (empty ?from) (not (at ?o1 ?from)) (not (at ?o2 ?from)) (not (at ?o2 l1)) (not (empty ?to))))
  (:action move-102  ; seen 20 times; carries ?o1 and ?o2 together
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (= ?to l4) (at ?o1 ?from) (at ?o2 l0) (clear ?o2) (empty ?to) (empty l3) (on ?o2 ?o1) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l3) (at ?o2 ?to) (at ?o2 l3) (empty ?from) (empty l0) (not (at ?o1 ?from)) (not (at ?o2 l0)) (not (empty ?to)) (not (empty l3))))
  (:action move-103  ; seen 20 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (= ?to l0) (at ?o1 ?from) (at ?o3 ?to) (clear ?o1) (clear ?o3) (empty l1) (empty l2) (on ?o1 ?o2) (on-table ?o3) (u2 ?o2) (u3 ?o1) (u3 ?o3) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (clear ?o2) (on ?o1 ?o3) (not (at ?o1 ?from)) (not (clear ?o3)) (not (empty l1)) (not (on ?o1 ?o2))))
  (:action move-104  ; seen 20 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l1) (= ?to l3) (at ?o1 ?from) (at ?o1 l2) (clear ?o1) (empty ?to) (empty l4) (on-table ?o1) (u5 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l4) (empty ?from) (empty l2) (not (at ?o1 ?from)) (not (at ?o1 l2)) (not (empty ?to)) (not (empty l4))))
  (:action move-105  ; seen 20 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o2 ?from) (at ?o2 ?to) (clear ?o2) (empty l0) (empty l3) (on ?o2 ?o1) (on-table ?o1) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o2 l0) (not (at ?o2 ?from)) (not (at ?o2 ?to)) (not (empty l0))))
  (:action move-109  ; seen 20 times; carries ?o1 and ?o2 together
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l1) (= ?to l3) (at ?o1 ?from) (at ?o2 l2) (empty ?to) (empty l4) (on ?o2 ?o1) (on-table ?o1) (u3 ?o2) (u5 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l4) (at ?o2 ?to) (at ?o2 l4) (empty ?from) (empty l2) (not (at ?o1 ?from)) (not (at ?o2 l2)) (not (empty ?to)) (not (empty l4))))
)
