! Example 4.3 of the paper from Fortran: the oscillator (4.1) with b = alpha
! = tau = 1, kernel H(s) = cos 2 pi s + cos 10 pi s + cos 20 pi s, forcing
! g(t) = 1.3 cos 8t and z = 0, in the first-order form (4.3) u = (w, v):
!   f(t, u) = (-v, b w + g(t)),  kernel [[0, 0], [H, 0]],  A = {0} x alpha sigma.
! The kernel and the right-hand side are Fortran callbacks (the model's data
! reach them as user data); the friction is the library's built-in one.
! Writes the CSV "t,w,v" of every stride-th t_p and of t = T to stdout, like
! examples/ex43.c.  Usage: ex43_fortran [N [T [stride]]] (defaults 9991, 30, 1).
! Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
module ex43_model
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_f_pointer
  implicit none
  private
  public :: oscillator, rhs, kernel

  real(c_double), parameter :: pi = 3.14159265358979323846_c_double

  ! The data of f: g(t) = amplitude * cos(omega t).
  type, bind(C) :: oscillator
    real(c_double) :: b, amplitude, omega
  end type oscillator

contains

  ! out = f(t, u) = (-v, b w + g(t)); user points to an oscillator.
  function rhs(t, u, out, user) result(rc) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: u(*)
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    type(oscillator), pointer :: m
    call c_f_pointer(user, m)
    out(1) = -u(2)
    out(2) = m%b * u(1) + m%amplitude * cos(m%omega * t)
    rc = 0
  end function rhs

  ! out = H(s): only entry (2, 1), index (2 - 1) * 2 + 1 = 3 in row-major order.
  function kernel(s, out, user) result(rc) bind(C)
    real(c_double), value :: s
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    out(3) = cos(2 * pi * s) + cos(10 * pi * s) + cos(20 * pi * s)
    rc = 0
  end function kernel

end module ex43_model

program ex43_fortran
  use, intrinsic :: iso_c_binding, only: c_int, c_size_t, c_double, c_ptr, c_null_ptr, &
                                         c_funloc, c_loc
  use, intrinsic :: iso_fortran_env, only: error_unit
  use dmi
  use ex43_model
  implicit none
  integer(c_size_t) :: n_tau, stride, p, steps
  real(c_double) :: t_end, u(2)
  real(c_double), parameter :: alpha(2) = [0.0_c_double, 1.0_c_double]
  type(oscillator), target :: model
  type(c_ptr) :: s
  ! N, T, stride as given (defaults 9991, 30, 1)
  character(len=64) :: args(3) = [character(len=64) :: '9991', '30', '1']
  integer :: i, ios(3)

  do i = 1, min(command_argument_count(), size(args))
    call get_command_argument(i, args(i))
  end do
  read (args(1), *, iostat=ios(1)) n_tau
  read (args(2), *, iostat=ios(2)) t_end
  read (args(3), *, iostat=ios(3)) stride
  if (any(ios /= 0) .or. n_tau < 1 .or. stride < 1) then
    write (error_unit, '(a)') 'usage: ex43_fortran [N [T [stride]]]'
    stop 2
  end if
  model = oscillator(1.0_c_double, 1.3_c_double, 8.0_c_double)

  s = c_null_ptr
  call check(dmi_create(s, 2_c_size_t, 1.0_c_double, n_tau), 'dmi_create')
  call check(dmi_set_rhs(s, c_funloc(rhs), c_loc(model)), 'dmi_set_rhs')
  call check(dmi_set_kernel(s, c_funloc(kernel), c_null_ptr), 'dmi_set_kernel')
  call check(dmi_set_friction(s, alpha), 'dmi_set_friction')
  call check(dmi_init(s), 'dmi_init')

  steps = nint(t_end / dmi_get_h(s), c_size_t)
  write (*, '(a)') 't,w,v'
  p = 0
  do
    call check(dmi_get_state(s, u), 'dmi_get_state')
    if (mod(p, stride) == 0 .or. p == steps) then
      write (*, '(a)') number(dmi_time(s)) // ',' // number(u(1)) // ',' // number(u(2))
    end if
    if (p == steps) exit
    call check(dmi_step(s), 'dmi_step')
    p = p + 1
  end do
  call dmi_free(s)

contains

  ! Stops with the library's messages if code is not DMI_OK.
  subroutine check(code, what)
    integer(c_int), intent(in) :: code
    character(len=*), intent(in) :: what
    if (code == DMI_OK) return
    write (error_unit, '(a)') 'ex43_fortran: ' // what // ': ' // dmi_strerror(code) // &
                              ' (' // dmi_last_error(s) // ')'
    call dmi_free(s)
    stop 1
  end subroutine check

  ! x with 17 significant digits, no blanks.
  function number(x) result(str)
    real(c_double), intent(in) :: x
    character(len=:), allocatable :: str
    character(len=32) :: buf
    write (buf, '(es25.16e3)') x
    str = trim(adjustl(buf))
  end function number
end program ex43_fortran
