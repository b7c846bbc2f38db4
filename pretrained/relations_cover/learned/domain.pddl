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
    (u4 ?x0 - item)
    (u5 ?x0 - item)
    (u6 ?x0 - item)
    (u7 ?x0 - item)
  )
  (:action move-0  ; seen 4138 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (clear ?o1) (empty ?to) (on-table ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to))))
  (:action move-1  ; seen 1907 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (clear ?o2) (on-table ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-2  ; seen 1572 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?from) (clear ?o1) (empty ?to) (on ?o1 ?o2) (u4 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (clear ?o2) (on-table ?o1) (not (at ?o1 ?from)) (not (empty ?to)) (not (on ?o1 ?o2))))
  (:action move-3  ; seen 444 times
    :parameters (?from - location ?o1 - item ?o2 - item ?o3 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?from) (at ?o3 ?to) (clear ?o1) (clear ?o3) (on ?o1 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)) (not (= ?o1 ?o3)) (not (= ?o2 ?o3)))
    :effect (and (at ?o1 ?to) (clear ?o2) (on ?o1 ?o3) (not (at ?o1 ?from)) (not (clear ?o3)) (not (on ?o1 ?o2))))
  (:action move-4  ; seen 205 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l0) (at ?o1 ?from) (clear ?o1) (empty ?to) (empty l1) (on-table ?o1) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l1))))
  (:action move-5  ; seen 182 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l2) (at ?o1 ?from) (clear ?o1) (empty ?to) (empty l1) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l1))))
  (:action move-6  ; seen 162 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (clear ?o2) (on-table ?o1) (u0 ?o2) (u5 ?o2) (u7 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o2 ?to)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-7  ; seen 154 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (clear ?o1) (empty ?to) (empty l0) (empty l2) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (at ?o1 l0) (at ?o1 l2) (empty ?from) (not (at ?o1 ?from)) (not (empty ?to)) (not (empty l0)) (not (empty l2))))
  (:action move-8  ; seen 128 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (at ?o1 ?from) (at ?o1 ?to) (clear ?o1) (on-table ?o1) (u0 ?o1) (not (= ?from ?to)))
    :effect (and (empty ?from) (not (at ?o1 ?from))))
  (:action move-18  ; seen 49 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l0) (at ?o1 ?from) (at ?o1 l1) (clear ?o1) (empty ?to) (on-table ?o1) (u5 ?o1) (u7 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l1) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (empty ?to))))
  (:action move-24  ; seen 38 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l2) (at ?o1 ?from) (at ?o2 l1) (clear ?o1) (clear ?o2) (empty ?to) (on-table ?o1) (on-table ?o2) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (at ?o2 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty ?to)) (not (on-table ?o1))))
  (:action move-27  ; seen 36 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l0) (at ?o1 ?from) (at ?o2 l1) (clear ?o1) (clear ?o2) (empty ?to) (on-table ?o1) (on-table ?o2) (u0 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l1) (at ?o2 ?to) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty ?to)) (not (on-table ?o1))))
  (:action move-28  ; seen 35 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l2) (at ?o1 ?from) (at ?o1 l1) (at ?o2 ?to) (on-table ?o1) (u0 ?o1) (u1 ?o2) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l1) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-30  ; seen 34 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (at ?o2 ?to) (clear ?o1) (empty l0) (empty l2) (on-table ?o1) (on-table ?o2) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (at ?o1 l0) (at ?o1 l2) (empty ?from) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (clear ?o2)) (not (empty l0)) (not (empty l2)) (not (on-table ?o1))))
  (:action move-31  ; seen 32 times
    :parameters (?from - location ?o1 - item ?o2 - item ?to - location)
    :precondition (and (= ?from l0) (at ?o1 ?from) (at ?o1 l1) (at ?o2 ?to) (clear ?o1) (on-table ?o1) (u1 ?o2) (u6 ?o1) (u7 ?o1) (not (= ?from ?to)) (not (= ?o1 ?o2)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l1) (on ?o1 ?o2) (not (at ?o1 ?from)) (not (at ?o1 l1)) (not (clear ?o2)) (not (on-table ?o1))))
  (:action move-36  ; seen 29 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?from l1) (at ?o1 ?from) (at ?o1 l0) (at ?o1 l2) (empty ?to) (on-table ?o1) (u0 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 ?to) (empty ?from) (empty l0) (empty l2) (not (at ?o1 ?from)) (not (at ?o1 l0)) (not (at ?o1 l2)) (not (empty ?to))))
  (:action move-44  ; seen 23 times
    :parameters (?from - location ?o1 - item ?to - location)
    :precondition (and (= ?to l1) (at ?o1 ?from) (at ?o1 ?to) (clear ?o1) (empty l0) (u0 ?o1) (not (= ?from ?to)))
    :effect (and (at ?o1 l0) (not (empty l0))))
)
