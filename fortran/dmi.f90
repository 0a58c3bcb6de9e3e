! Fortran 2003 binding of libdmi: module dmi, an ISO_C_BINDING mirror of
! include/dmi.h (read it for what every procedure does; the comments here
! only say how the Fortran side differs).
!
! - Same procedure names and argument order as the C API.  The solver handle
!   is a type(c_ptr); user data is a type(c_ptr) (e.g. c_loc of a variable
!   with the target attribute), passed back to the callbacks untouched.
! - Callbacks are bind(C) functions matching the abstract interfaces
!   dmi_rhs_fn, dmi_resolvent_fn, dmi_kernel_fn and dmi_history_fn, passed
!   with c_funloc; c_null_funptr resets the callback (as NULL does in C).
! - Arrays are ordinary real(c_double) arrays.  Matrices H(s) come row-major
!   as in C: entry (i, j) (1-based) is out((i - 1) * n + j).
! - dmi_version, dmi_last_error and dmi_strerror return a Fortran string
!   (a copy), not a C pointer.
! - dmi_set_kernel_exp (since 1.1) needs the array d (C accepts NULL for all
!   D_k = 0: pass zeros).  c and d hold K n x n matrices, each row-major as
!   above: entry (i, j) of term k (1-based) is c((k - 1) * n * n + (i - 1) * n + j).
! - dmi_get_step_terms needs both arrays (C accepts NULL for either), and so
!   does dmi_get_kernel_weights (since 1.5): count * n * n values each.
! - The tangent (since 1.6): dmi_tangent_create takes the other models'
!   handles as an array of type(c_ptr); dmi_tangent_set_history,
!   dmi_tangent_sample_history and dmi_tangent_set_rhs_parameters need their
!   arrays (C accepts NULL for a default: pass zeros, or 1 for every
!   parameter the history or f depends on), and dmi_tangent_run
!   needs every array (C accepts NULL for all but s_out: pass zeros for dwu);
!   switches is an array of integer(c_int8_t).  Arrays are row-major as in C:
!   S of step q (0-based), component i, parameter j (1-based) is
!   s_out((q * n + i - 1) * p + j).
! - The state buffer of dmi_state_save / dmi_state_load is an array of
!   integer(c_int8_t) of dmi_state_size(s) elements.
! - C's size_t is integer(c_size_t), uint64_t is integer(c_int64_t).
!
! Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
module dmi
  use, intrinsic :: iso_c_binding, only: c_int, c_size_t, c_int64_t, c_int8_t, c_double, &
                                         c_ptr, c_funptr, c_char, c_associated, c_f_pointer
  implicit none
  private

  ! Version of this binding (the same as the C header it mirrors).
  integer(c_int), parameter, public :: DMI_VERSION_MAJOR = 1
  integer(c_int), parameter, public :: DMI_VERSION_MINOR = 6
  integer(c_int), parameter, public :: DMI_VERSION_PATCH = 0

  ! Error codes.
  integer(c_int), parameter, public :: DMI_OK = 0
  integer(c_int), parameter, public :: DMI_EINVAL = -1
  integer(c_int), parameter, public :: DMI_ENOMEM = -2
  integer(c_int), parameter, public :: DMI_ECALLBACK = -3
  integer(c_int), parameter, public :: DMI_ENONFINITE = -4
  integer(c_int), parameter, public :: DMI_ESTATE = -5

  ! Methods of computing the delay sum (dmi_set_convolution).
  integer(c_int), parameter, public :: DMI_CONV_AUTO = 0
  integer(c_int), parameter, public :: DMI_CONV_DIRECT = 1
  integer(c_int), parameter, public :: DMI_CONV_FFT = 2
  integer(c_int), parameter, public :: DMI_CONV_RECURSIVE = 3 ! (since 1.1)
  ! Quadrature rules of the delay sum (since 1.3), see dmi_set_quadrature.
  integer(c_int), parameter, public :: DMI_QUAD_LEFT = 0
  integer(c_int), parameter, public :: DMI_QUAD_CELL = 1
  ! The tangent (since 1.6): the flag of dmi_tangent_run and the switches it reports.
  integer(c_int), parameter, public :: DMI_TANGENT_PLAIN = 1
  integer(c_int), parameter, public :: DMI_SWITCH_NONE = 0
  integer(c_int), parameter, public :: DMI_SWITCH_STICK = 1
  integer(c_int), parameter, public :: DMI_SWITCH_REVERSAL = 2
  integer(c_int), parameter, public :: DMI_SWITCH_UNPLACED = 3

  public :: dmi_rhs_fn, dmi_resolvent_fn, dmi_kernel_fn, dmi_history_fn
  public :: dmi_version, dmi_create, dmi_create_h, dmi_free
  public :: dmi_set_rhs, dmi_set_resolvent, dmi_set_friction, dmi_set_box
  public :: dmi_set_kernel, dmi_set_kernel_exp, dmi_set_history, dmi_set_convolution
  public :: dmi_set_quadrature, dmi_set_kernel_near, dmi_set_kernel_singularity
  public :: dmi_init, dmi_step, dmi_advance
  public :: dmi_time, dmi_get_step_index, dmi_get_h, dmi_get_N, dmi_get_state, dmi_get_past
  public :: dmi_get_step_terms, dmi_get_window, dmi_set_window, dmi_get_kernel_weights
  public :: dmi_state_size, dmi_state_save, dmi_state_load
  public :: dmi_tangent_create, dmi_tangent_set_history, dmi_tangent_sample_history
  public :: dmi_tangent_set_kernel_terms, dmi_tangent_set_rhs_parameters
  public :: dmi_tangent_run, dmi_tangent_free
  public :: dmi_last_error, dmi_strerror

  ! The callbacks.  Each returns 0 on success, anything else makes the calling
  ! library function fail with DMI_ECALLBACK.  out is zeroed before every call
  ! (except for the resolvent, which must write all n values).
  abstract interface
    ! out = f(t, u), n values.
    function dmi_rhs_fn(t, u, out, user) result(rc) bind(C)
      import :: c_int, c_double, c_ptr
      real(c_double), value :: t
      real(c_double), intent(in) :: u(*)
      real(c_double), intent(inout) :: out(*)
      type(c_ptr), value :: user
      integer(c_int) :: rc
    end function dmi_rhs_fn

    ! out = (I + lambda A)^{-1} x, n values.
    function dmi_resolvent_fn(lambda, x, out, user) result(rc) bind(C)
      import :: c_int, c_double, c_ptr
      real(c_double), value :: lambda
      real(c_double), intent(in) :: x(*)
      real(c_double), intent(inout) :: out(*)
      type(c_ptr), value :: user
      integer(c_int) :: rc
    end function dmi_resolvent_fn

    ! out = H(s), n*n values, row-major, 0 <= s < tau.
    function dmi_kernel_fn(s, out, user) result(rc) bind(C)
      import :: c_int, c_double, c_ptr
      real(c_double), value :: s
      real(c_double), intent(inout) :: out(*)
      type(c_ptr), value :: user
      integer(c_int) :: rc
    end function dmi_kernel_fn

    ! out = z(t), n values, -tau <= t <= 0.
    function dmi_history_fn(t, out, user) result(rc) bind(C)
      import :: c_int, c_double, c_ptr
      real(c_double), value :: t
      real(c_double), intent(inout) :: out(*)
      type(c_ptr), value :: user
      integer(c_int) :: rc
    end function dmi_history_fn
  end interface

  interface
    ! ---- life cycle ----------------------------------------------------
    ! n_tau is the paper's N (steps per delay tau; Fortran names ignore case).
    function dmi_create(out, n, tau, n_tau) result(rc) bind(C, name='dmi_create')
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), intent(out) :: out
      integer(c_size_t), value :: n
      real(c_double), value :: tau
      integer(c_size_t), value :: n_tau
      integer(c_int) :: rc
    end function dmi_create

    ! (libdmi 1.2) h given, tau / h need not be an integer (dmi.h: the last
    ! cell of the delay sum is weighted theta h, N = ceiling(tau / h)).
    function dmi_create_h(out, n, tau, h) result(rc) bind(C, name='dmi_create_h')
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), intent(out) :: out
      integer(c_size_t), value :: n
      real(c_double), value :: tau, h
      integer(c_int) :: rc
    end function dmi_create_h

    subroutine dmi_free(s) bind(C, name='dmi_free')
      import :: c_ptr
      type(c_ptr), intent(inout) :: s
    end subroutine dmi_free

    ! ---- setup -----------------------------------------------------------
    function dmi_set_rhs(s, f, user) result(rc) bind(C, name='dmi_set_rhs')
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: s
      type(c_funptr), value :: f
      type(c_ptr), value :: user
      integer(c_int) :: rc
    end function dmi_set_rhs

    function dmi_set_resolvent(s, r, user) result(rc) bind(C, name='dmi_set_resolvent')
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: s
      type(c_funptr), value :: r
      type(c_ptr), value :: user
      integer(c_int) :: rc
    end function dmi_set_resolvent

    function dmi_set_friction(s, alpha) result(rc) bind(C, name='dmi_set_friction')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      real(c_double), intent(in) :: alpha(*)
      integer(c_int) :: rc
    end function dmi_set_friction

    function dmi_set_box(s, lo, hi) result(rc) bind(C, name='dmi_set_box')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      real(c_double), intent(in) :: lo(*), hi(*)
      integer(c_int) :: rc
    end function dmi_set_box

    function dmi_set_kernel(s, h, user) result(rc) bind(C, name='dmi_set_kernel')
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: s
      type(c_funptr), value :: h
      type(c_ptr), value :: user
      integer(c_int) :: rc
    end function dmi_set_kernel

    function dmi_set_kernel_exp(s, k, a, b, c, d) result(rc) bind(C, name='dmi_set_kernel_exp')
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: s
      integer(c_size_t), value :: k
      real(c_double), intent(in) :: a(*), b(*), c(*), d(*)
      integer(c_int) :: rc
    end function dmi_set_kernel_exp

    function dmi_set_history(s, z, user) result(rc) bind(C, name='dmi_set_history')
      import :: c_int, c_ptr, c_funptr
      type(c_ptr), value :: s
      type(c_funptr), value :: z
      type(c_ptr), value :: user
      integer(c_int) :: rc
    end function dmi_set_history

    ! (since 1.3) rule = DMI_QUAD_LEFT (the default) or DMI_QUAD_CELL; before dmi_init.
    function dmi_set_quadrature(s, rule) result(rc) bind(C, name='dmi_set_quadrature')
      import :: c_ptr, c_int
      type(c_ptr), value :: s
      integer(c_int), value :: rule
      integer(c_int) :: rc
    end function dmi_set_quadrature
    ! (since 1.3) the exact kernel h on the cells below delta, the exponential
    ! sum of dmi_set_kernel_exp beyond; before dmi_init.
    function dmi_set_kernel_near(s, h, user, delta) result(rc) bind(C, name='dmi_set_kernel_near')
      import :: c_int, c_ptr, c_funptr, c_double
      type(c_ptr), value :: s
      type(c_funptr), value :: h
      type(c_ptr), value :: user
      real(c_double), value :: delta
      integer(c_int) :: rc
    end function dmi_set_kernel_near
    ! (since 1.4) the exponent alpha (0 <= alpha < 1) of the kernel's singularity
    ! s^-alpha at 0 for the cell rule and the near cells, or NaN (the default) to
    ! estimate it; before dmi_init.
    function dmi_set_kernel_singularity(s, alpha) result(rc) &
        bind(C, name='dmi_set_kernel_singularity')
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: s
      real(c_double), value :: alpha
      integer(c_int) :: rc
    end function dmi_set_kernel_singularity
    function dmi_set_convolution(s, method) result(rc) bind(C, name='dmi_set_convolution')
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      integer(c_int), value :: method
      integer(c_int) :: rc
    end function dmi_set_convolution

    ! ---- time stepping -----------------------------------------------------
    function dmi_init(s) result(rc) bind(C, name='dmi_init')
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      integer(c_int) :: rc
    end function dmi_init

    function dmi_step(s) result(rc) bind(C, name='dmi_step')
      import :: c_int, c_ptr
      type(c_ptr), value :: s
      integer(c_int) :: rc
    end function dmi_step

    function dmi_advance(s, steps) result(rc) bind(C, name='dmi_advance')
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: s
      integer(c_size_t), value :: steps
      integer(c_int) :: rc
    end function dmi_advance

    ! ---- queries -------------------------------------------------------------
    function dmi_time(s) result(t) bind(C, name='dmi_time')
      import :: c_double, c_ptr
      type(c_ptr), value :: s
      real(c_double) :: t
    end function dmi_time

    function dmi_get_step_index(s, p) result(rc) bind(C, name='dmi_get_step_index')
      import :: c_int, c_int64_t, c_ptr
      type(c_ptr), value :: s
      integer(c_int64_t), intent(out) :: p
      integer(c_int) :: rc
    end function dmi_get_step_index

    function dmi_get_h(s) result(h) bind(C, name='dmi_get_h')
      import :: c_double, c_ptr
      type(c_ptr), value :: s
      real(c_double) :: h
    end function dmi_get_h

    ! (libdmi 1.2) N, the delay sum's cells: the window has N + 1 rows.
    ! (Fortran ignores case: dmi_get_N and dmi_get_n are one name.)
    function dmi_get_N(s) result(n_tau) bind(C, name='dmi_get_N')
      import :: c_size_t, c_ptr
      type(c_ptr), value :: s
      integer(c_size_t) :: n_tau
    end function dmi_get_N

    function dmi_get_state(s, u) result(rc) bind(C, name='dmi_get_state')
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: s
      real(c_double), intent(out) :: u(*)
      integer(c_int) :: rc
    end function dmi_get_state

    function dmi_get_past(s, lag, u) result(rc) bind(C, name='dmi_get_past')
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: s
      integer(c_size_t), value :: lag
      real(c_double), intent(out) :: u(*)
      integer(c_int) :: rc
    end function dmi_get_past

    ! (since 1.2) u holds (N + 1) * n values: row k (0-based) at u(k * n + 1 : k * n + n).
    function dmi_get_window(s, u) result(rc) bind(C, name='dmi_get_window')
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: s
      real(c_double), intent(out) :: u(*)
      integer(c_int) :: rc
    end function dmi_get_window

    function dmi_set_window(s, u) result(rc) bind(C, name='dmi_set_window')
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: s
      real(c_double), intent(in) :: u(*)
      integer(c_int) :: rc
    end function dmi_set_window

    ! (since 1.5) the delay sum's weights G_l of the lags first .. first + count - 1
    ! (0-based), as the steps use them, and the near cells' part of them: lag l's
    ! n x n matrix row-major at g((l - first) * n * n + 1 : (l - first + 1) * n * n).
    function dmi_get_kernel_weights(s, first, count, g, g_near) result(rc) &
        bind(C, name='dmi_get_kernel_weights')
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: s
      integer(c_size_t), value :: first, count
      real(c_double), intent(out) :: g(*), g_near(*)
      integer(c_int) :: rc
    end function dmi_get_kernel_weights

    function dmi_get_step_terms(s, w, x) result(rc) bind(C, name='dmi_get_step_terms')
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: s
      real(c_double), intent(out) :: w(*), x(*)
      integer(c_int) :: rc
    end function dmi_get_step_terms

    ! ---- saving and restoring the time-stepping state --------------------------
    function dmi_state_size(s) result(size) bind(C, name='dmi_state_size')
      import :: c_size_t, c_ptr
      type(c_ptr), value :: s
      integer(c_size_t) :: size
    end function dmi_state_size

    function dmi_state_save(s, buf, size) result(rc) bind(C, name='dmi_state_save')
      import :: c_int, c_size_t, c_int8_t, c_ptr
      type(c_ptr), value :: s
      integer(c_int8_t), intent(out) :: buf(*)
      integer(c_size_t), value :: size
      integer(c_int) :: rc
    end function dmi_state_save

    function dmi_state_load(s, buf, size) result(rc) bind(C, name='dmi_state_load')
      import :: c_int, c_size_t, c_int8_t, c_ptr
      type(c_ptr), value :: s
      integer(c_int8_t), intent(in) :: buf(*)
      integer(c_size_t), value :: size
      integer(c_int) :: rc
    end function dmi_state_load

    ! ---- sensitivities: the tangent of the scheme (since 1.6) --------------
    ! p is the number of parameters P; others(1:p) the handles of the models at
    ! p + delta_j e_j.
    function dmi_tangent_create(out, s, p, others, delta) result(rc) &
        bind(C, name='dmi_tangent_create')
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), intent(out) :: out
      type(c_ptr), value :: s
      integer(c_size_t), value :: p
      type(c_ptr), intent(in) :: others(*)
      real(c_double), intent(in) :: delta(*)
      integer(c_int) :: rc
    end function dmi_tangent_create

    function dmi_tangent_set_history(t, s0) result(rc) bind(C, name='dmi_tangent_set_history')
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: t
      real(c_double), intent(in) :: s0(*)
      integer(c_int) :: rc
    end function dmi_tangent_set_history

    function dmi_tangent_sample_history(t, columns) result(rc) &
        bind(C, name='dmi_tangent_sample_history')
      import :: c_int, c_ptr
      type(c_ptr), value :: t
      integer(c_int), intent(in) :: columns(*)
      integer(c_int) :: rc
    end function dmi_tangent_sample_history

    ! (dd: pass zeros where C accepts NULL)
    function dmi_tangent_set_kernel_terms(t, da, db, dc, dd) result(rc) &
        bind(C, name='dmi_tangent_set_kernel_terms')
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: t
      real(c_double), intent(in) :: da(*), db(*), dc(*), dd(*)
      integer(c_int) :: rc
    end function dmi_tangent_set_kernel_terms

    function dmi_tangent_set_rhs_parameters(t, depends) result(rc) &
        bind(C, name='dmi_tangent_set_rhs_parameters')
      import :: c_int, c_ptr
      type(c_ptr), value :: t
      integer(c_int), intent(in) :: depends(*)
      integer(c_int) :: rc
    end function dmi_tangent_set_rhs_parameters

    function dmi_tangent_run(t, steps, flags, dwu, u, x, s_out, dx, switches) result(rc) &
        bind(C, name='dmi_tangent_run')
      import :: c_int, c_size_t, c_double, c_int8_t, c_ptr
      type(c_ptr), value :: t
      integer(c_size_t), value :: steps
      integer(c_int), value :: flags
      real(c_double), intent(in) :: dwu(*)
      real(c_double), intent(out) :: u(*), x(*), s_out(*), dx(*)
      integer(c_int8_t), intent(out) :: switches(*)
      integer(c_int) :: rc
    end function dmi_tangent_run

    subroutine dmi_tangent_free(t) bind(C, name='dmi_tangent_free')
      import :: c_ptr
      type(c_ptr), intent(inout) :: t
    end subroutine dmi_tangent_free
  end interface

  ! The C functions behind the string-returning procedures.
  interface
    function c_dmi_version() result(p) bind(C, name='dmi_version')
      import :: c_ptr
      type(c_ptr) :: p
    end function c_dmi_version

    function c_dmi_last_error(s) result(p) bind(C, name='dmi_last_error')
      import :: c_ptr
      type(c_ptr), value :: s
      type(c_ptr) :: p
    end function c_dmi_last_error

    function c_dmi_strerror(code) result(p) bind(C, name='dmi_strerror')
      import :: c_int, c_ptr
      integer(c_int), value :: code
      type(c_ptr) :: p
    end function c_dmi_strerror

    function c_strlen(p) result(n) bind(C, name='strlen')
      import :: c_size_t, c_ptr
      type(c_ptr), value :: p
      integer(c_size_t) :: n
    end function c_strlen
  end interface

contains

  ! "MAJOR.MINOR.PATCH" of the library actually linked.
  function dmi_version() result(v)
    character(len=:), allocatable :: v
    v = fortran_string(c_dmi_version())
  end function dmi_version

  ! Message of the last failure on s (copied; "" if none).
  function dmi_last_error(s) result(msg)
    type(c_ptr), intent(in) :: s
    character(len=:), allocatable :: msg
    msg = fortran_string(c_dmi_last_error(s))
  end function dmi_last_error

  ! Description of an error code.
  function dmi_strerror(code) result(msg)
    integer(c_int), intent(in) :: code
    character(len=:), allocatable :: msg
    msg = fortran_string(c_dmi_strerror(code))
  end function dmi_strerror

  ! Copy of the NUL-terminated C string p ("" for a null pointer).
  function fortran_string(p) result(str)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: str
    character(kind=c_char), pointer :: chars(:)
    integer :: i, n
    if (.not. c_associated(p)) then
      str = ''
      return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate(character(len=n) :: str)
    do i = 1, n
      str(i:i) = chars(i)
    end do
  end function fortran_string

end module dmi
