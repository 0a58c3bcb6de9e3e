! Test of the Fortran binding of the tangent (dmi_tangent_*, libdmi 1.6): the
! sensitivity dU^q/da of u' + a u = 0, u = 1 on [-tau, 0], against the exact
! derivative of the scheme, U^q = (1 - h a)^q, dU^q/da = -q h (1 - h a)^(q-1);
! and a refusal with its message.
! Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
module tangent_model
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_f_pointer
  implicit none

  type, bind(C) :: decay_data
    real(c_double) :: a
  end type decay_data

contains

  ! f(t, u) = a u.
  function decay(t, u, out, user) result(rc) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: u(*)
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    type(decay_data), pointer :: d
    call c_f_pointer(user, d)
    out(1) = d%a * u(1)
    rc = 0
  end function decay

  ! z(t) = 1.
  function one(t, out, user) result(rc) bind(C)
    real(c_double), value :: t
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    out(1) = 1
    rc = 0
  end function one

end module tangent_model

program test_tangent
  use, intrinsic :: iso_c_binding, only: c_int, c_int8_t, c_size_t, c_double, c_ptr, &
                                         c_funloc, c_loc, c_associated
  use dmi
  use tangent_model
  implicit none
  integer, parameter :: steps = 50, n_tau = 4
  real(c_double), parameter :: tau = 1, h = tau / n_tau
  type(decay_data), target :: base, other
  type(c_ptr) :: s, o, t
  type(c_ptr) :: others(1)
  real(c_double) :: delta(1), dwu(steps), u(steps + 1), x(steps), sens(steps + 1), dx(steps)
  real(c_double) :: s0(n_tau + 1), exact
  integer(c_int8_t) :: switches(steps)
  integer :: failures = 0, q

  base%a = 0.8_c_double
  other%a = base%a + 2.0_c_double**(-26)
  delta(1) = other%a - base%a
  call make(s, base)
  call make(o, other)
  others(1) = o
  call check(dmi_tangent_create(t, s, 1_c_size_t, others, delta) == DMI_OK, 'dmi_tangent_create')
  s0 = 0
  call check(dmi_tangent_set_history(t, s0) == DMI_OK, 'dmi_tangent_set_history')
  call check(dmi_tangent_set_rhs_parameters(t, [1_c_int]) == DMI_OK, &
             'dmi_tangent_set_rhs_parameters')
  dwu = 0
  call check(dmi_tangent_run(t, int(steps, c_size_t), 0_c_int, dwu, u, x, sens, dx, switches) &
             == DMI_OK, 'dmi_tangent_run: ' // dmi_last_error(s))
  do q = 0, steps
    call check(abs(u(q + 1) - (1 - h * base%a)**q) <= 1e-14_c_double, 'U^q')
    exact = -q * h * (1 - h * base%a)**(q - 1)
    call check(abs(sens(q + 1) - exact) <= 1e-6_c_double * abs(exact) + 1e-12_c_double, 'dU^q/da')
  end do
  call check(all(switches == DMI_SWITCH_NONE), 'switches without friction')
  call check(dmi_tangent_run(t, 0_c_size_t, DMI_TANGENT_PLAIN, dwu, u, x, sens, dx, switches) &
             == DMI_EINVAL, 'dmi_tangent_run with steps = 0')
  call check(index(dmi_last_error(s), 'steps = 0') > 0, 'the message names steps')
  call dmi_tangent_free(t)
  call check(.not. c_associated(t), 'dmi_tangent_free sets the handle to NULL')
  call dmi_free(o)
  call dmi_free(s)
  if (failures > 0) then
    print '(i0, a)', failures, ' check(s) failed'
    stop 1
  end if
  print '(a)', 'Fortran tangent: all checks passed'

contains

  subroutine make(solver, d)
    type(c_ptr), intent(out) :: solver
    type(decay_data), target, intent(inout) :: d
    call check(dmi_create(solver, 1_c_size_t, tau, int(n_tau, c_size_t)) == DMI_OK, 'dmi_create')
    call check(dmi_set_rhs(solver, c_funloc(decay), c_loc(d)) == DMI_OK, 'dmi_set_rhs')
    call check(dmi_set_history(solver, c_funloc(one), c_loc(d)) == DMI_OK, 'dmi_set_history')
    call check(dmi_init(solver) == DMI_OK, 'dmi_init')
  end subroutine make

  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (ok) return
    failures = failures + 1
    print '(2a)', 'FAIL: ', what
  end subroutine check

end program test_tangent
