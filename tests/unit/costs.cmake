# The slowest unit tests' run times in seconds (Release, 2 cores, ctest -j2), given to ctest as
# their COST: ctest starts the costliest first, so that a clean build (no timing history of its
# own yet) does not start a 80 s test last while the other core idles. A build's own history,
# once it has one (Testing/Temporary/CTestCostData.txt), takes over.
set(rigcal_slow_tests
    Session.HandEyeRunsRigcalsOdometryOnTheMotionScans 50
    CheckSim.AnUnchangedRigIsConsistentAndATurnedCameraIsFlaggedOnItself 78
    GroundTruthSim.AShortWalksMarkersAndTrajectoryAgainstTheTruth 49
    Session.CalibrateNamesTheFailedStepThenRerunsOnlyIt 42
    Session.CalibrateOnBagsIsCalibrateOnTheirConversionAndOnTheFolders 40
    CameraSim.EquidistantMeetsTheTruthBar 28
    LidarCameraSim.TenPairsWithClutter 26
    CameraSim.AprilGridSeedOneAgainstTheIssuesBars 25
    CameraSim.RadtanMeetsTheTruthBar 23
    CameraSim.AWarpedBoardIsRecoveredAndTheBiasItCausedGoes 21
    Deskew.EstimatingEachSweepsMotionFollowsAWalkBetter 19
    Session.DetectionsAreReusedOnlyOnTheSameImages 17
    OdometryOnADrive.BagsOfTheScansStreamToTheSameTrajectory 16
    OdometryOnADrive.BadScansAreSkippedAndCountedNeverAJump 15
    RealReport.AcfrLidarCameraPairs 14
    DiffReport.LoadsInChromiumAndRendersAgainFromItsJson 13
    Cli.LidarCameraWritesTheRigAndRefusesTooFewBoards 13
    RealReport.OpenCvStereoSamples 12
    SequenceBa.AWalksWindowsGiveMotionsBetterThanTheOdometrysWithHonestSigmas 11
    Steps.CamerasWritesBothCamerasAndReusesItsDetections 10
    CaptureSim.TwoCamerasRecordingCalibratesAsTheImagesItRecorded 25
    CaptureSim.ACameraLostMidStreamIsNamedAndWhatWasRecordedKept 17)
list(LENGTH rigcal_slow_tests n)
math(EXPR last "${n} - 1")
foreach(i RANGE 0 ${last} 2)
  math(EXPR j "${i} + 1")
  list(GET rigcal_slow_tests ${i} name)
  list(GET rigcal_slow_tests ${j} cost)
  set_tests_properties(${name} PROPERTIES COST ${cost})
endforeach()

# The capture tests serve Aravis' GigE Vision simulator on 127.0.0.1:3956: one at a time.
foreach(name CaptureSim.FeaturesAreSetAndReadBackAndTheMissingDefaultsReported
             CaptureSim.TheCommandRecordsAndRefusesBadInputWithExitTwo
             CaptureSim.ARequiredFeatureAbsentOrRefusedIsNamedAndNothingIsWritten
             CaptureSim.SoftwareTriggeredFramesAreCountedAndEqualTheSimulatorsImages
             CaptureSim.AnInterruptMidStreamLosesNothing
             CaptureSim.ACameraLostMidStreamIsNamedAndWhatWasRecordedKept
             CaptureSim.AWriterFallingBehindStopsTheRecordingAndWritesWhatWasReceived
             CaptureSim.TwoCamerasRecordingCalibratesAsTheImagesItRecorded)
  set_tests_properties(${name} PROPERTIES RESOURCE_LOCK gige_simulator)
endforeach()
