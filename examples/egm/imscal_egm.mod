MODULE imscal_egm
  ! The robot program's path played by `imscal serve --protocol egm` over ABB EGM in position
  ! guidance (RobotWare 6.x/7.x with the Externally Guided Motion option). The server streams the
  ! program's desired joints (its --path) plus the precontrol's correction; this module only
  ! brings the robot to the path's first pose and hands the motion to EGM while the server plays.
  !
  ! Controller configuration (in words; see the README's EGM section):
  !  - Communication > Transmission Protocol: a UDPUC device named "imscal" whose remote address
  !    and port are the PC running `imscal serve` and its --port.
  !  - Motion > External Motion Interface Data: the profile "default" (or one of its own) with
  !    the EGM filtering level, the default ramp times and the position gain.
  VAR egmident egm_id;
  ! Convergence: each joint within 0.1 degrees of its target ends EGMRunJoint's start phase.
  CONST egm_minmax egm_converged := [-0.1, 0.1];
  ! The path's first pose (the first row of the served robot.csv, in degrees).
  CONST jointtarget path_start := [[0, -90, 90, 0, 45, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];

  PROC main()
    ! At rest on the path's first pose: the server starts the path only there.
    MoveAbsJ path_start, v100, fine, tool0;
    EGMReset egm_id;
    EGMGetId egm_id;
    ! Joint mode over the UDP device "imscal", profile "default"; the controller stops EGM when
    ! no answer came for 1 s.
    EGMSetupUC ROB_1, egm_id, "default", "imscal" \Joint \CommTimeout := 1;
    ! 4 ms sampling, the EGM low-pass filter at 20 Hz, a large allowed deviation (the server's
    ! corrections are mrad; its targets follow the program's path).
    EGMActJoint egm_id \J1 := egm_converged \J2 := egm_converged \J3 := egm_converged
      \J4 := egm_converged \J5 := egm_converged \J6 := egm_converged
      \SampleRate := 4 \LpFilter := 20 \MaxSpeedDeviation := 100;
    ! Returns once every joint has stayed within egm_converged of its target for CondTime [s]:
    ! at the path's end, which the server holds (keep the path's rests shorter than CondTime);
    ! position gain 1: the robot's target is the server's target.
    EGMRunJoint egm_id, EGM_STOP_HOLD \J1 \J2 \J3 \J4 \J5 \J6 \CondTime := 2
      \RampInTime := 0.05 \PosCorrGain := 1;
    EGMReset egm_id;
  ENDPROC
ENDMODULE
