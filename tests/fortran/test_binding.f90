! Test of the Fortran binding (module dmi): every procedure called from
! Fortran, with Fortran callbacks and user data, against values computed here:
! the recurrence (3.12)-(3.13) written out for a linear model, the resolvents
! of the box and of the friction by hand, and the documented error codes.
! Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
module binding_model
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_f_pointer
  implicit none
  integer, parameter :: n = 2, n_tau = 4
  real(c_double), parameter :: tau = 1, h = tau / n_tau, k_a = 0.5_c_double, c = 0.7_c_double

  ! User data of the right-hand side f(t, u) = (a1 u1, a2 u2 + t).
  type, bind(C) :: rhs_data
    real(c_double) :: a(n)
    integer(c_int) :: fail ! nonzero: the callback fails
  end type rhs_data

contains

  function rhs(t, u, out, user) result(rc) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: u(*)
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    type(rhs_data), pointer :: d
    call c_f_pointer(user, d)
    out(1) = d%a(1) * u(1)
    out(2) = d%a(2) * u(2) + t
    rc = d%fail
  end function rhs

  ! H(s) = [[c, 0], [s, 0]], row-major.
  function kernel(s, out, user) result(rc) bind(C)
    real(c_double), value :: s
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    out(1) = c
    out(3) = s
    rc = 0
  end function kernel

  ! z(t) = (1 + t, 2 - t).
  function history(t, out, user) result(rc) bind(C)
    real(c_double), value :: t
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    out(1) = 1 + t
    out(2) = 2 - t
    rc = 0
  end function history

  ! z(t) = (1, -1).
  function constant_history(t, out, user) result(rc) bind(C)
    real(c_double), value :: t
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    out(1) = 1
    out(2) = -1
    rc = 0
  end function constant_history

  ! Resolvent of A = k_a I: out = x / (1 + lambda k_a).
  function resolvent(lambda, x, out, user) result(rc) bind(C)
    real(c_double), value :: lambda
    real(c_double), intent(in) :: x(*)
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    out(1:n) = x(1:n) / (1 + lambda * k_a)
    rc = 0
  end function resolvent

end module binding_model

program test_binding
  use, intrinsic :: iso_c_binding, only: c_int, c_int8_t, c_int64_t, c_size_t, c_double, &
                                         c_ptr, c_null_ptr, c_null_funptr, c_funloc, c_loc, &
                                         c_associated
  use dmi
  use binding_model
  implicit none
  integer, parameter :: p_max = 40
  integer(c_int), parameter :: methods(3) = [DMI_CONV_DIRECT, DMI_CONV_FFT, DMI_CONV_RECURSIVE]
  ! The scheme written out: ue(:, p) = U^p, we(:, p) = W^p, xe(:, p) = X^p.
  real(c_double) :: ue(n, -n_tau:p_max), we(n, 0:p_max), xe(n, 0:p_max)
  type(rhs_data), target :: data
  type(c_ptr) :: s
  real(c_double) :: u(n), w(n), x(n), ua(n)
  integer(c_int8_t), allocatable :: buf(:)
  integer(c_int64_t) :: index
  integer :: failures = 0, p, lag, i
  character(len=32) :: expected_version
  character(len=:), allocatable :: message

  ! ---- version, strings, NULL handles -----------------------------------
  write (expected_version, '(i0, ".", i0, ".", i0)') DMI_VERSION_MAJOR, DMI_VERSION_MINOR, &
      DMI_VERSION_PATCH
  call check(dmi_version() == trim(expected_version), 'dmi_version() = ' // dmi_version())
  call check(dmi_strerror(12345_c_int) == 'unknown error code', 'dmi_strerror(12345)')
  message = dmi_strerror(DMI_EINVAL)
  call check(len(message) > 0, 'dmi_strerror(DMI_EINVAL) is empty')
  call check(message /= dmi_strerror(DMI_ESTATE), 'dmi_strerror of two codes are the same')
  call check(len(dmi_last_error(c_null_ptr)) > 0, 'dmi_last_error(NULL) is empty')
  call check(dmi_get_h(c_null_ptr) == 0, 'dmi_get_h(NULL)')
  call check(dmi_time(c_null_ptr) == 0, 'dmi_time(NULL)')
  call check(dmi_state_size(c_null_ptr) == 0, 'dmi_state_size(NULL)')
  s = c_null_ptr
  call check(dmi_create(s, 0_c_size_t, tau, int(n_tau, c_size_t)) == DMI_EINVAL, &
             'dmi_create with n = 0')
  call check(.not. c_associated(s), 'dmi_create failed but set a handle')
  call check(dmi_create(s, int(n, c_size_t), -1.0_c_double, int(n_tau, c_size_t)) == DMI_EINVAL, &
             'dmi_create with tau < 0')

  ! ---- solver with Fortran f, H, z and resolvent ---------------------------
  call expect_ok(dmi_create(s, int(n, c_size_t), tau, int(n_tau, c_size_t)), 'dmi_create')
  call check(c_associated(s), 'dmi_create gave no handle')
  call check(dmi_get_h(s) == h, 'dmi_get_h')
  call check(dmi_step(s) == DMI_ESTATE, 'dmi_step before dmi_init')
  call check(len(dmi_last_error(s)) > 0, 'no message after a failure')
  call check(dmi_get_state(s, u) == DMI_ESTATE, 'dmi_get_state before dmi_init')
  data = rhs_data([-0.3_c_double, 0.2_c_double], 0)
  call expect_ok(dmi_set_rhs(s, c_funloc(rhs), c_loc(data)), 'dmi_set_rhs')
  call expect_ok(dmi_set_kernel(s, c_funloc(kernel), c_null_ptr), 'dmi_set_kernel')
  call expect_ok(dmi_set_history(s, c_funloc(history), c_null_ptr), 'dmi_set_history')
  call expect_ok(dmi_set_box(s, [-5.0_c_double, -5.0_c_double], [5.0_c_double, 5.0_c_double]), &
                 'dmi_set_box')
  call expect_ok(dmi_set_resolvent(s, c_funloc(resolvent), c_null_ptr), 'dmi_set_resolvent')
  call expect_ok(dmi_set_convolution(s, DMI_CONV_DIRECT), 'dmi_set_convolution')
  call check(dmi_set_convolution(s, 99_c_int) == DMI_EINVAL, 'dmi_set_convolution(99)')
  call expect_ok(dmi_init(s), 'dmi_init')
  call check(dmi_set_kernel(s, c_null_funptr, c_null_ptr) == DMI_ESTATE, 'dmi_set_kernel after init')
  call check(dmi_get_step_terms(s, w, x) == DMI_ESTATE, 'dmi_get_step_terms before a step')

  do p = -n_tau, 0
    ue(:, p) = [1 + p * h, 2 - p * h]
  end do
  p = 0
  call check_solver()
  do i = 1, 6
    call expect_ok(dmi_step(s), 'dmi_step')
    call expected_step(.true.)
    call check_solver()
  end do
  call expect_ok(dmi_advance(s, 3_c_size_t), 'dmi_advance')
  do i = 1, 3
    call expected_step(.true.)
  end do
  call check_solver()

  ! A failing callback leaves the solver as it was; the retry is the step.
  data%fail = 7
  call check(dmi_step(s) == DMI_ECALLBACK, 'dmi_step with a failing f')
  call check(len(dmi_last_error(s)) > 0, 'no message after DMI_ECALLBACK')
  call check_solver()
  data%fail = 0
  call expect_ok(dmi_step(s), 'dmi_step after the failure')
  call expected_step(.true.)
  call check_solver()

  ! Save, go on, restore, go on again: the same states.
  allocate(buf(dmi_state_size(s)))
  call check(size(buf) > 0, 'dmi_state_size')
  call expect_ok(dmi_state_save(s, buf, size(buf, kind=c_size_t)), 'dmi_state_save')
  call expect_ok(dmi_advance(s, 2_c_size_t), 'dmi_advance')
  call expect_ok(dmi_get_state(s, ua), 'dmi_get_state')
  call expect_ok(dmi_state_load(s, buf, size(buf, kind=c_size_t)), 'dmi_state_load')
  call check_solver()
  call expect_ok(dmi_advance(s, 2_c_size_t), 'dmi_advance')
  call expect_ok(dmi_get_state(s, u), 'dmi_get_state')
  call check(all(u == ua), 'stepping from a restored state differs')
  do i = 1, 2
    call expected_step(.true.)
  end do
  call check_solver()
  buf(size(buf) / 2) = ieor(buf(size(buf) / 2), 1_c_int8_t)
  call check(dmi_state_load(s, buf, size(buf, kind=c_size_t)) == DMI_EINVAL, 'corrupted state loaded')
  call check(dmi_state_load(s, buf, size(buf, kind=c_size_t) - 1) == DMI_EINVAL, 'short state loaded')
  call check_solver()

  ! f = NULL restores f = 0.
  call expect_ok(dmi_set_rhs(s, c_null_funptr, c_null_ptr), 'dmi_set_rhs(NULL)')
  call expect_ok(dmi_step(s), 'dmi_step with f = 0')
  call expected_step(.false.)
  call check_solver()
  call dmi_free(s)
  call check(.not. c_associated(s), 'dmi_free did not reset the handle')
  call dmi_free(s)

  ! ---- the built-in resolvents: box, then friction ----------------------------
  call expect_ok(dmi_create(s, int(n, c_size_t), tau, int(n_tau, c_size_t)), 'dmi_create')
  call expect_ok(dmi_set_history(s, c_funloc(constant_history), c_null_ptr), 'dmi_set_history')
  call check(dmi_set_box(s, [1.0_c_double, 0.0_c_double], [0.0_c_double, 1.0_c_double]) == DMI_EINVAL, &
             'dmi_set_box with lo > hi')
  call expect_ok(dmi_set_box(s, [0.0_c_double, 0.0_c_double], [0.5_c_double, 0.5_c_double]), &
                 'dmi_set_box')
  call expect_ok(dmi_init(s), 'dmi_init')
  call expect_ok(dmi_step(s), 'dmi_step')
  call expect_ok(dmi_get_state(s, u), 'dmi_get_state')
  call check(all(u == [0.5_c_double, 0.0_c_double]), 'projection onto the box')
  call check(dmi_set_friction(s, [-1.0_c_double, 0.0_c_double]) == DMI_EINVAL, &
             'dmi_set_friction with alpha < 0')
  call expect_ok(dmi_set_friction(s, [1.0_c_double, 2.0_c_double]), 'dmi_set_friction')
  call expect_ok(dmi_step(s), 'dmi_step')
  call expect_ok(dmi_get_state(s, u), 'dmi_get_state')
  ! soft threshold of (0.5, 0) by h alpha = (0.25, 0.5)
  call check(all(u == [0.25_c_double, 0.0_c_double]), 'friction resolvent')
  call expect_ok(dmi_get_step_index(s, index), 'dmi_get_step_index')
  call check(index == 2, 'step index after two steps')
  call dmi_free(s)

  ! ---- an exponential kernel (libdmi 1.1), summed by the recursion ------------
  ! H(s) = [[0.5 exp(-s), 0], [0.2 cos 3s, 0.1 sin 3s]], z = (1, -1), f = 0:
  ! W^0 = h sum_{l<4} H(l h) (1, -1), written out here.
  call expect_ok(dmi_create(s, int(n, c_size_t), tau, int(n_tau, c_size_t)), 'dmi_create')
  call expect_ok(dmi_set_history(s, c_funloc(constant_history), c_null_ptr), 'dmi_set_history')
  call expect_ok(dmi_set_kernel(s, c_funloc(kernel), c_null_ptr), 'dmi_set_kernel')
  call check(dmi_set_convolution(s, DMI_CONV_RECURSIVE) == DMI_EINVAL, &
             'RECURSIVE accepted a callback kernel')
  call check(dmi_set_kernel_exp(s, 0_c_size_t, [0.0_c_double], [0.0_c_double], [0.0_c_double], &
             [0.0_c_double]) == DMI_EINVAL, 'dmi_set_kernel_exp with K = 0')
  call expect_ok(dmi_set_kernel_exp(s, 2_c_size_t, [-1.0_c_double, 0.0_c_double], &
                 [0.0_c_double, 3.0_c_double], &
                 [0.5_c_double, 0.0_c_double, 0.0_c_double, 0.0_c_double, &
                  0.0_c_double, 0.0_c_double, 0.2_c_double, 0.0_c_double], &
                 [0.0_c_double, 0.0_c_double, 0.0_c_double, 0.0_c_double, &
                  0.0_c_double, 0.0_c_double, 0.0_c_double, 0.1_c_double]), 'dmi_set_kernel_exp')
  call expect_ok(dmi_set_convolution(s, DMI_CONV_RECURSIVE), 'dmi_set_convolution(RECURSIVE)')
  call expect_ok(dmi_init(s), 'dmi_init')
  call expect_ok(dmi_step(s), 'dmi_step')
  call expect_ok(dmi_get_step_terms(s, w, x), 'dmi_get_step_terms')
  we(:, 0) = 0
  do lag = 0, n_tau - 1
    we(1, 0) = we(1, 0) + h * 0.5_c_double * exp(-lag * h)
    we(2, 0) = we(2, 0) + h * (0.2_c_double * cos(3 * lag * h) - 0.1_c_double * sin(3 * lag * h))
  end do
  call check(all(abs(w - we(:, 0)) <= 1e-15_c_double), 'W^0 of the exponential kernel')
  call dmi_free(s)

  ! ---- a step that need not divide tau (libdmi 1.2) ---------------------------
  ! h = tau / 3.5: N = 4 cells, the last weighted h / 2; the same kernel and z,
  ! every method: W^0 = h sum_{l<3} H(l h) (1, -1) + (h / 2) H(3 h) (1, -1).
  call check(dmi_create_h(s, int(n, c_size_t), tau, 0.0_c_double) == DMI_EINVAL, &
             'dmi_create_h with h = 0')
  call check(.not. c_associated(s), 'dmi_create_h failed but set a handle')
  call check(dmi_get_N(c_null_ptr) == 0, 'dmi_get_N(NULL)')
  do i = 1, 3
    call expect_ok(dmi_create_h(s, int(n, c_size_t), tau, tau / 3.5_c_double), 'dmi_create_h')
    call check(dmi_get_N(s) == 4, 'dmi_get_N')
    call check(dmi_get_h(s) == tau / 3.5_c_double, 'dmi_get_h of dmi_create_h')
    call expect_ok(dmi_set_history(s, c_funloc(constant_history), c_null_ptr), 'dmi_set_history')
    call expect_ok(dmi_set_kernel_exp(s, 2_c_size_t, [-1.0_c_double, 0.0_c_double], &
                   [0.0_c_double, 3.0_c_double], &
                   [0.5_c_double, 0.0_c_double, 0.0_c_double, 0.0_c_double, &
                    0.0_c_double, 0.0_c_double, 0.2_c_double, 0.0_c_double], &
                   [0.0_c_double, 0.0_c_double, 0.0_c_double, 0.0_c_double, &
                    0.0_c_double, 0.0_c_double, 0.0_c_double, 0.1_c_double]), 'dmi_set_kernel_exp')
    call expect_ok(dmi_set_convolution(s, methods(i)), 'dmi_set_convolution')
    call expect_ok(dmi_init(s), 'dmi_init')
    call expect_ok(dmi_step(s), 'dmi_step')
    call expect_ok(dmi_get_step_terms(s, w, x), 'dmi_get_step_terms')
    we(:, 0) = 0
    do lag = 0, 3
      ua = [0.5_c_double * exp(-lag * (tau / 3.5_c_double)), &
            0.2_c_double * cos(3 * lag * (tau / 3.5_c_double)) &
            - 0.1_c_double * sin(3 * lag * (tau / 3.5_c_double))]
      we(:, 0) = we(:, 0) + merge(0.5_c_double, 1.0_c_double, lag == 3) * (tau / 3.5_c_double) * ua
    end do
    call check(all(abs(w - we(:, 0)) <= 1e-15_c_double), 'W^0 with the partial last cell')
    call dmi_free(s)
  end do
  deallocate(buf, message) ! (main program variables are not freed at its end)

  if (failures > 0) then
    print '(i0, a)', failures, ' failure(s)'
    stop 1
  end if
  print '(a)', 'Fortran binding: all checks passed'

contains

  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (ok) return
    failures = failures + 1
    print '(a, i0, 2a)', 'FAIL (p = ', p, '): ', what
  end subroutine check

  subroutine expect_ok(code, what)
    integer(c_int), intent(in) :: code
    character(len=*), intent(in) :: what
    call check(code == DMI_OK, what // ': ' // dmi_strerror(code) // ' (' // dmi_last_error(s) // ')')
  end subroutine expect_ok

  ! U^{p+1}, W^p and X^p of the scheme; f on or off, resolvent of k_a I.
  subroutine expected_step(with_f)
    logical, intent(in) :: with_f
    real(c_double) :: f(n)
    integer :: l
    we(:, p) = 0
    do l = 0, n_tau - 1
      we(1, p) = we(1, p) + c * ue(1, p - l)
      we(2, p) = we(2, p) + (l * h) * ue(1, p - l)
    end do
    we(:, p) = h * we(:, p)
    f = 0
    if (with_f) f = [data%a(1) * ue(1, p), data%a(2) * ue(2, p) + p * h]
    xe(:, p) = ue(:, p) - h * f - h * we(:, p)
    ue(:, p + 1) = xe(:, p) / (1 + h * k_a)
    p = p + 1
  end subroutine expected_step

  ! The solver at step p agrees with ue, we, xe.
  subroutine check_solver()
    real(c_double), parameter :: tol = 1e-13_c_double
    call expect_ok(dmi_get_step_index(s, index), 'dmi_get_step_index')
    call check(index == p, 'step index')
    call check(dmi_time(s) == p * h, 'dmi_time')
    call expect_ok(dmi_get_state(s, u), 'dmi_get_state')
    call check(all(abs(u - ue(:, p)) <= tol), 'U^p')
    do lag = 0, n_tau
      call expect_ok(dmi_get_past(s, int(lag, c_size_t), u), 'dmi_get_past')
      call check(all(abs(u - ue(:, p - lag)) <= tol), 'U^{p-lag}')
    end do
    call check(dmi_get_past(s, int(n_tau + 1, c_size_t), u) == DMI_EINVAL, 'dmi_get_past(N + 1)')
    if (p > 0) then
      call expect_ok(dmi_get_step_terms(s, w, x), 'dmi_get_step_terms')
      call check(all(abs(w - we(:, p - 1)) <= tol), 'W^{p-1}')
      call check(all(abs(x - xe(:, p - 1)) <= tol), 'X^{p-1}')
    end if
  end subroutine check_solver

end program test_binding
