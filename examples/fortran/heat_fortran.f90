!> heat_fortran: the heat_c example in Fortran, instrumented through the `insitu` module.
!>
!>   heat_fortran ARCHIVE [STEPS [interior|float]]
!>
!> Heat diffuses from three hot spots held at temperature 1 through a unit cube of 32^3 samples,
!> with one ghost layer on every side held at 0 (cold walls). The configuration is written to
!> ARCHIVE.json and read back with insitu_create_from_file; every 10th step goes to ARCHIVE, and
!> the field is handed over only on those steps (insitu_selects).
!> With "interior", the array section without the ghost layers is handed over instead of the
!> whole array and its ghost count: a section that is not contiguous, passed with its strides and
!> still without a copy. With "float", a real(c_float) copy is handed over (the renderers work in
!> single precision anyway). All three ways give the same pictures. The arrays are ordinary
!> allocatables, without the TARGET attribute: the library reads them in place until
!> insitu_execute returns.
!> Exits 0 when every call succeeded, 1 when any failed (the run still goes to the end), 2 for
!> bad arguments.
program heat_fortran
    use, intrinsic :: iso_c_binding, only: c_double, c_float, c_int
    use, intrinsic :: iso_fortran_env, only: error_unit
    use insitu
    implicit none

    integer, parameter :: n = 32       ! interior samples per axis
    integer, parameter :: ghosts = 1   ! ghost layers on each side
    ! Hot spots: centre (interior sample coordinates, from 0) and radius in samples.
    real(c_double), parameter :: spots(4, 3) = reshape([9.0d0, 10.0d0, 12.0d0, 3.0d0, &
                                                        22.0d0, 20.0d0, 16.0d0, 4.0d0, &
                                                        14.0d0, 24.0d0, 23.0d0, 2.5d0], [4, 3])
    ! alpha dt / dx^2 of explicit Euler; at most 1/6 in 3D for stability.
    real(c_double), parameter :: diffusion_number = 0.15d0

    ! temperature(i, j, k) with i (x) fastest: Fortran's column-major order is libinsitu's
    ! x-fastest layout, so the array goes to the library as it is. Indices 0 and n + 1 are the
    ! ghost layers; the lower bound does not matter to the module (it sees shape only).
    real(c_double), allocatable :: temperature(:, :, :)
    real(c_double), allocatable :: next(:, :, :)
    real(c_float), allocatable :: temperature_float(:, :, :)  ! "float" mode only
    type(insitu_instrument) :: instrument
    character(len=4096) :: archive, argument
    character(len=:), allocatable :: config_path
    real(c_double) :: spacing, dt
    integer(c_int) :: status
    integer :: steps, step, failures, stored, argument_count, io_status
    character(len=16) :: mode

    argument_count = command_argument_count()
    if (argument_count < 1 .or. argument_count > 3) then
        write (error_unit, '(a)') "usage: heat_fortran ARCHIVE [STEPS [interior|float]]"
        stop 2, quiet=.true.
    end if
    call get_command_argument(1, archive)
    steps = 40
    if (argument_count >= 2) then
        call get_command_argument(2, argument)
        read (argument, *, iostat=io_status) steps
        if (io_status /= 0 .or. steps < 1) then
            write (error_unit, '(3a)') "heat_fortran: STEPS = ", trim(argument), &
                " is not a positive integer"
            stop 2, quiet=.true.
        end if
    end if

    mode = "whole"
    if (argument_count == 3) then
        call get_command_argument(3, argument)
        if (trim(argument) /= "interior" .and. trim(argument) /= "float") then
            write (error_unit, '(3a)') "heat_fortran: unknown mode ", trim(argument), &
                " (expected interior or float)"
            stop 2, quiet=.true.
        end if
        mode = argument(1:len(mode))
    end if

    config_path = trim(archive)//".json"
    call write_config(config_path, trim(archive))
    status = insitu_create_from_file(config_path, instrument)
    if (status /= INSITU_OK) then
        ! A bad configuration is found at start-up; the simulation decides what to do.
        write (error_unit, '(4a)') "heat_fortran: ", insitu_status_name(status), ": ", &
            insitu_last_error()
        stop 1, quiet=.true.
    end if

    allocate (temperature(0:n + 1, 0:n + 1, 0:n + 1), next(0:n + 1, 0:n + 1, 0:n + 1))
    temperature = 0.0d0
    next = 0.0d0
    spacing = 1.0d0 / n
    dt = diffusion_number * spacing**2  ! diffusivity 1 world unit^2 per unit time
    call apply_sources(temperature)

    failures = 0
    stored = 0
    do step = 1, steps
        ! 7-point Laplacian on the interior; the ghosts keep the walls' temperature 0.
        next(1:n, 1:n, 1:n) = temperature(1:n, 1:n, 1:n) + diffusion_number * ( &
                              temperature(0:n - 1, 1:n, 1:n) + temperature(2:n + 1, 1:n, 1:n) + &
                              temperature(1:n, 0:n - 1, 1:n) + temperature(1:n, 2:n + 1, 1:n) + &
                              temperature(1:n, 1:n, 0:n - 1) + temperature(1:n, 1:n, 2:n + 1) - &
                              6.0d0 * temperature(1:n, 1:n, 1:n))
        temperature(1:n, 1:n, 1:n) = next(1:n, 1:n, 1:n)
        call apply_sources(temperature)

        ! Only the steps the configuration keeps need the field (and, in "float" mode, its copy);
        ! insitu_execute is called every step all the same.
        status = INSITU_OK
        if (insitu_selects(instrument, step)) then
            select case (mode)
            case ("interior")
                status = insitu_set_field(instrument, "temperature", &
                                          temperature(1:n, 1:n, 1:n), &
                                          origin=[0.0d0, 0.0d0, 0.0d0], &
                                          spacing=[spacing, spacing, spacing])
            case ("float")
                temperature_float = real(temperature, c_float)
                status = insitu_set_field(instrument, "temperature", temperature_float, &
                                          origin=[0.0d0, 0.0d0, 0.0d0], &
                                          spacing=[spacing, spacing, spacing], &
                                          ghosts=[ghosts, ghosts, ghosts])
            case default
                status = insitu_set_field(instrument, "temperature", temperature, &
                                          origin=[0.0d0, 0.0d0, 0.0d0], &
                                          spacing=[spacing, spacing, spacing], &
                                          ghosts=[ghosts, ghosts, ghosts])
            end select
        end if
        if (status == INSITU_OK) status = insitu_execute(instrument, step, step * dt)
        if (status < 0) then
            ! Report and go on: the simulation is worth more than its pictures.
            write (error_unit, '(a, i0, 4a)') "heat_fortran: step ", step, ": ", &
                insitu_status_name(status), ": ", insitu_last_error()
            failures = failures + 1
        else if (status /= INSITU_NOT_SELECTED) then
            write (*, '(a, i0, 2a)') "step ", step, ": ", insitu_status_name(status)
            if (status == INSITU_OK) stored = stored + 1
        end if
    end do

    status = insitu_finalize(instrument)
    if (status /= INSITU_OK) then
        write (error_unit, '(4a)') "heat_fortran: finalize: ", insitu_status_name(status), ": ", &
            insitu_last_error()
        failures = failures + 1
    end if
    call insitu_destroy(instrument)
    ! The main program's allocatables are saved, never freed on their own: freed here, so that
    ! this loop copied into a subroutine that runs once per simulation does not leak each run.
    deallocate (temperature, next, config_path)
    if (allocated(temperature_float)) deallocate (temperature_float)
    write (*, '(a, i0, a, i0, 3a, i0, a)') "heat_fortran: ", steps, " steps, ", stored, &
        " stored in ", trim(archive), ", ", failures, " failures"
    if (failures /= 0) stop 1, quiet=.true.

contains

    !> Holds the hot spots at temperature 1, so the field does not fade to nothing.
    subroutine apply_sources(t)
        real(c_double), intent(inout) :: t(0:, 0:, 0:)
        integer :: i, j, k, s
        do s = 1, size(spots, 2)
            do k = 0, n - 1
                do j = 0, n - 1
                    do i = 0, n - 1
                        if ((i - spots(1, s))**2 + (j - spots(2, s))**2 + (k - spots(3, s))**2 &
                            <= spots(4, s)**2) t(i + ghosts, j + ghosts, k + ghosts) = 1.0d0
                    end do
                end do
            end do
        end do
    end subroutine apply_sources

    !> Writes the run's configuration: two 32x32 views (seconds on a CPU OpenCL device), a
    !> transfer function over the field's range [0, 1] with opacity per 0.1 world units (the
    !> cube is 1 wide), every 10th step, into `archive_path`.
    subroutine write_config(path, archive_path)
        character(len=*), intent(in) :: path, archive_path
        integer :: unit
        open (newunit=unit, file=path, status="replace", action="write")
        write (unit, '(a)') '{"fields": ["temperature"],'
        write (unit, '(a)') ' "views": [{"azimuth": 30, "elevation": 20, "size": [32, 32]},'
        write (unit, '(a)') '           {"azimuth": 120, "elevation": -10, "camera": "perspective",'
        write (unit, '(a)') '            "fov": 30, "size": [32, 32]}],'
        write (unit, '(a)') ' "transfer_function": {"points": [[0.0, 0, 0, 1, 0],'
        write (unit, '(a)') '     [0.3, 0, 1, 0, 0.2], [1.0, 1, 0, 0, 0.8]], "unit_length": 0.1},'
        write (unit, '(a)') ' "layers": "auto", "intervals": {"count": 8, "mode": "uniform"},'
        write (unit, '(3a)') ' "every": 10, "archive": "', json_escaped(archive_path), '",'
        write (unit, '(a)') ' "writer": {"queue": 2, "when_full": "block"}}'
        close (unit)
    end subroutine write_config

    !> `text` with JSON's string escapes for '"' and '\'.
    function json_escaped(text) result(escaped)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: escaped
        integer :: i
        escaped = ""
        do i = 1, len(text)
            if (text(i:i) == '"' .or. text(i:i) == '\') escaped = escaped//'\'
            escaped = escaped//text(i:i)
        end do
    end function json_escaped

end program heat_fortran
