! The Fortran side of tests/abi/consumer: module dmi and libdmi_fortran from
! an installed prefix.  Same check as consumer.c: n = 1, A = 0, f = 0,
! H(s) = c, z = 1, against U^{p+1} = U^p - h * h c sum_{l=0}^{N-1} U^{p-l}.
! Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
module consumer_callbacks
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_f_pointer
  implicit none
contains
  function kernel(s, out, user) result(rc) bind(C)
    real(c_double), value :: s
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    real(c_double), pointer :: c
    call c_f_pointer(user, c)
    out(1) = c
    rc = 0
  end function kernel

  function history(t, out, user) result(rc) bind(C)
    real(c_double), value :: t
    real(c_double), intent(inout) :: out(*)
    type(c_ptr), value :: user
    integer(c_int) :: rc
    out(1) = 1
    rc = 0
  end function history
end module consumer_callbacks

program consumer_fortran
  use, intrinsic :: iso_c_binding, only: c_size_t, c_double, c_ptr, c_null_ptr, c_funloc, c_loc
  use dmi
  use consumer_callbacks
  implicit none
  integer, parameter :: n_tau = 8, steps = 40
  real(c_double), target :: c = 3
  real(c_double) :: h, u(1), big_u(0:n_tau + steps)
  character(len=32) :: expected
  type(c_ptr) :: s
  integer :: p

  write (expected, '(i0, ".", i0, ".", i0)') DMI_VERSION_MAJOR, DMI_VERSION_MINOR, DMI_VERSION_PATCH
  if (dmi_version() /= trim(expected)) stop 'dmi_version() differs from the module''s version'

  h = 1.0_c_double / n_tau
  if (dmi_create(s, 1_c_size_t, 1.0_c_double, int(n_tau, c_size_t)) /= DMI_OK) stop 'dmi_create'
  if (dmi_set_kernel(s, c_funloc(kernel), c_loc(c)) /= DMI_OK) stop 'dmi_set_kernel'
  if (dmi_set_history(s, c_funloc(history), c_null_ptr) /= DMI_OK) stop 'dmi_set_history'
  if (dmi_init(s) /= DMI_OK) stop 'dmi_init'
  if (dmi_advance(s, int(steps, c_size_t)) /= DMI_OK) stop 'dmi_advance'
  if (dmi_get_state(s, u) /= DMI_OK) stop 'dmi_get_state'
  call dmi_free(s)

  big_u(0:n_tau) = 1 ! big_u(k) = U^{k - N}
  do p = 0, steps - 1
    big_u(n_tau + p + 1) = big_u(n_tau + p) - h * (h * c * sum(big_u(p + 1:n_tau + p)))
  end do
  if (.not. abs(u(1) - big_u(n_tau + steps)) <= 1e-13_c_double * abs(big_u(n_tau + steps))) then
    print *, 'U^40 =', u(1), ' expected', big_u(n_tau + steps)
    stop 1
  end if
  print '(3a, es23.16, a)', 'ok (Fortran, libdmi ', dmi_version(), ', U^40 = ', u(1), ')'
end program consumer_fortran
